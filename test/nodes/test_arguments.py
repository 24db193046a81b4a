# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Issue 22 cases 5 and 6: every entry point turns a bad argument, a ROS argument rcl refuses and
absurd physics into one ``error:`` line on stderr and exit code 2 (no traceback), before any work.

The entry points run in this process (``main(args)``), so the rcl log line that used to come
with a refused command line would be seen by ``capfd`` too.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vib_estimator import cli
from vib_estimator.nodes import bag_replayer, estimator_node, sim_node

ROOT = Path(__file__).resolve().parents[2]
BAG = ROOT / 'bags' / 'fig1'


#: a node that starts although it should not is stopped after this long (the test then fails)
WATCHDOG_S = 20.0


def _exit_code(main, args):
    """``main(args)``'s exit code; a node still running after WATCHDOG_S is shut down."""
    import threading

    import rclpy

    watchdog = threading.Timer(WATCHDOG_S, rclpy.try_shutdown)
    watchdog.start()
    try:
        return main(args)
    except SystemExit as stop:
        return stop.code
    finally:
        watchdog.cancel()


def _assert_one_error_line(capfd, code, *words):
    out, err = capfd.readouterr()
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 2, err
    assert len(lines) == 1 and 'error: ' in lines[0] and 'Traceback' not in err, err
    for word in words:
        assert word in lines[0], (word, lines[0])
    return out


@pytest.mark.parametrize(
    'ros_args,word',
    [
        (['-p'], '-p'),
        (['--params-file', '/nonexistent.yaml'], '/nonexistent.yaml'),
        (['-r', 'remap_without_colon'], 'remap_without_colon'),
        (['-r', 'vibration/frequency:=1bad'], '1bad'),
        (['-p', 'input_topic:=1bad'], '1bad'),
        (['-p', 'min_fit:=2.0'], 'min_fit'),
        (['-p', 'gap_intervals:=1.5'], 'gap_intervals'),
    ],
)
def test_estimator_node_refuses_bad_ros_arguments_in_one_line(capfd, ros_args, word):
    code = _exit_code(estimator_node.main, ['estimator_node', '--ros-args', *ros_args])
    _assert_one_error_line(capfd, code, word)


@pytest.mark.parametrize(
    'override,word',
    [
        ('schedule:=[]', 'schedule'),
        ('schedule:=[0.0, 1.0, 1.0, 1000.0]', 'physical range'),  # f0 0.009 Hz
        ('tip_mass_kg:=1000.0', 'tip_mass_kg'),
    ],
)
def test_sim_node_refuses_an_empty_schedule_and_absurd_masses(capfd, override, word):
    code = _exit_code(sim_node.main, ['sim_node', '--ros-args', '-p', override])
    _assert_one_error_line(capfd, code, word)


@pytest.mark.parametrize(
    'override', ['start_offset:=1e300', 'delay:=1e300', 'wait_timeout:=1e300', 'clock_hz:=1e9']
)
def test_bag_replayer_refuses_absurd_times_and_rates(capfd, override):
    if not BAG.exists():
        pytest.skip('bags/fig1 not built')
    code = _exit_code(
        bag_replayer.main, ['bag_replayer', '--ros-args', '-p', f'bag:={BAG}', '-p', override]
    )
    _assert_one_error_line(capfd, code, override.split(':=')[0])


@pytest.mark.parametrize(
    'argv,word',
    [
        (['demo', '--domain-id', '-1'], '--domain-id'),
        (['analyze'], 'input'),
        (['reproduce', 'fig1', '--out', '/proc/x.png'], '/proc/x.png'),
    ],
)
def test_cli_refuses_bad_arguments_in_one_line(capfd, argv, word):
    _assert_one_error_line(capfd, _exit_code(cli.main, argv), word)


def test_analyze_checks_the_plot_path_before_the_analysis(capfd, tmp_path):
    t = np.arange(0, 5, 0.002)
    path = tmp_path / 'sine.csv'
    np.savetxt(path, np.c_[t, np.sin(2 * np.pi * 3 * t)], delimiter=',', header='t,y', comments='')
    code = _exit_code(cli.main, ['analyze', str(path), '--plot', '/proc/x.png'])
    out = _assert_one_error_line(capfd, code, '--plot /proc/x.png')
    assert out == ''  # no estimate printed: nothing was analysed
