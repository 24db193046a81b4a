# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The figures, checked for what a reader needs on them (labels, units, legend entries, the marked
modes) through the matplotlib Figure each plotting function returns; and ``analyze``'s summary."""

import json
import re

import numpy as np
import pytest

from vib_estimator.analysis import compare, reproduce
from vib_estimator.analysis.analyze import estimate_signal, plot_run
from vib_estimator.analysis.summary import ModeSummary, recommend_shaper, summarise_modes
from vib_estimator.cli import main
from vib_estimator.control import __main__ as sensitivity_cli
from vib_estimator.control.shaping import EI_VTOL, SHAPERS, design, sensitivity
from vib_estimator.core import EstimatorConfig
from vib_estimator.io.bags import WrenchSeries, write_wrench_series
from vib_estimator.io.fields import UNKNOWN_UNIT, signal_unit
from vib_estimator.io.streaming import open_signal

F0 = 1.33


def legend_texts(ax):
    legend = ax.get_legend()
    return [t.get_text() for t in legend.get_texts()] if legend else []


def sine(seed=5, f=F0, zeta=0.0, duration=8.0):
    rng = np.random.default_rng(seed)
    t = np.arange(0, duration, 0.002)
    envelope = np.exp(-zeta * 2 * np.pi * f * t)
    y = 0.2 * envelope * np.sin(2 * np.pi * f * np.sqrt(1 - zeta**2) * t + 0.4)
    return t, y + 0.002 * rng.standard_normal(len(t))


@pytest.mark.parametrize(
    'name, unit',
    [
        ('torque.z', 'N·m'),
        ('force.x', 'N'),
        ('linear_acceleration.z', 'm/s²'),
        ('angular_velocity.y', 'rad/s'),
        ('accel.linear.z', 'm/s²'),
        ('effort[joint1]', 'N·m or N'),
        ('accel_g', 'g'),
        ('tip_velocity_m_s', 'm/s'),
        ('hub_angle_rad', 'rad'),
        ('motor_voltage_V', 'V'),
        ('torque (N·m)', 'N·m'),
        ('acc [mg]', 'mg'),
        ('data', UNKNOWN_UNIT),
        ('y', UNKNOWN_UNIT),
        ('1', UNKNOWN_UNIT),
        ('vector.z', UNKNOWN_UNIT),
    ],
)
def test_signal_unit_of_components_and_columns(name, unit):
    assert signal_unit(name) == unit


def test_analyze_plot_has_the_unit_and_the_spectrum_with_the_modes_marked(tmp_path):
    t, y = sine()
    stamps = 1_700_000_000_000_000_000 + np.round(t * 1e9).astype(np.int64)
    write_wrench_series(tmp_path / 'bag', WrenchSeries(stamps, y, 'arm', '/coupling_torque'))
    signal = open_signal(tmp_path / 'bag')
    run = estimate_signal(signal, EstimatorConfig(), keep_samples=True)
    fig = plot_run(str(tmp_path / 'a.png'), 'bag', signal, run)
    assert (tmp_path / 'a.png').exists()
    signal_ax, est_ax, conv_ax, psd_ax = fig.axes
    assert signal_ax.get_ylabel() == '/coupling_torque torque.z (N·m)'
    assert 'algebraic estimates' in legend_texts(est_ax)
    assert psd_ax.get_xlabel() == 'frequency (Hz)' and psd_ax.get_ylabel() == 'PSD ((N·m)²/Hz)'
    median = float(np.median(run.estimates.frequency_hz))
    labels = legend_texts(psd_ax)
    assert labels[0] == 'Welch PSD' and labels[1:] == [f'f = {median:.5g} Hz']
    psd_line, mark = psd_ax.get_lines()
    assert np.allclose(mark.get_xdata(), median)
    f, p = psd_line.get_data()
    assert abs(f[np.argmax(p)] - F0) <= 1.5 * (f[1] - f[0])  # the marked mode is the peak
    assert psd_ax.get_xlim()[0] <= median <= psd_ax.get_xlim()[1]


def test_analyze_plot_of_two_modes_marks_both_and_a_bare_column_says_signal_units(tmp_path):
    t, y1 = sine()
    _, y2 = sine(seed=6, f=7.9)
    path = tmp_path / 's.csv'
    np.savetxt(path, np.column_stack([t, y1 + 0.5 * y2]), delimiter=',', header='t,y', comments='')
    signal = open_signal(path)
    run = estimate_signal(signal, EstimatorConfig(modes=2), keep_samples=True)
    fig = plot_run(str(tmp_path / 'b.png'), 's.csv', signal, run, run.estimates.mode)
    assert fig.axes[0].get_ylabel() == f'y ({UNKNOWN_UNIT})'
    psd_ax = fig.axes[3]
    marks = sorted(float(line.get_xdata()[0]) for line in psd_ax.get_lines()[1:])
    assert len(marks) == 2
    assert abs(marks[0] / F0 - 1) < 0.01 and abs(marks[1] / 7.9 - 1) < 0.01
    assert [x for x in legend_texts(psd_ax) if x.startswith('f = ')] == [
        f'f = {marks[0]:.5g} Hz (mode 1)',
        f'f = {marks[1]:.5g} Hz (mode 2)',
    ]


def summary_of(err):
    lines = [line.removeprefix('analyze: ') for line in err.splitlines()]
    return lines[lines.index('modes found:') :]


def test_analyze_summary_gives_the_modes_and_the_shaper_node_command(tmp_path, capsys):
    t, y = sine(zeta=0.004, duration=12.0)
    path = tmp_path / 'decay.csv'
    np.savetxt(path, np.column_stack([t, y]), delimiter=',', header='t,torque', comments='')
    assert main(['analyze', str(path), '--model', 'damped-sinusoid']) == 0
    out = capsys.readouterr()
    rows = [json.loads(line) for line in out.out.splitlines()]  # stdout stays jsonl
    f = np.array([r['frequency_hz'] for r in rows])
    zeta = np.array([r['damping'] for r in rows])
    summary = summary_of(out.err)
    mode = re.match(
        r'  mode: f = ([\d.]+) ± ([\d.e-]+) Hz \(robust std of (\d+) estimates.*'
        r'damping ratio ([\d.]+)$',
        summary[1],
    )
    assert mode, summary
    assert float(mode[1]) == pytest.approx(np.median(f), abs=1e-4)
    mad = np.median(np.abs(f - np.median(f)))
    assert float(mode[2]) == pytest.approx(1.4826 * mad, rel=0.05)
    assert int(mode[3]) == len(rows) > 3
    assert float(mode[4]) == pytest.approx(0.004, abs=0.001)
    assert summary[2].startswith('recommended input shaper: ZVD')
    command = re.fullmatch(
        r'  ros2 run vib_estimator shaper_node --ros-args -p shaper:=(\w+) '
        r'-p initial_frequency_hz:=([\d.]+) -p damping_ratio:=([\d.]+)',
        summary[3],
    )
    assert command, summary[3]
    assert command[1] == 'zvd' and command[1] in SHAPERS
    assert float(command[2]) == pytest.approx(F0 * np.sqrt(1 - 0.004**2), rel=0.002)
    assert float(command[3]) == pytest.approx(np.median(zeta), abs=1e-4)
    assert '.' in command[3]  # a double literal: shaper_node's type


def test_analyze_summary_without_damping_designs_for_zero_and_no_estimate_no_summary(
    tmp_path, capsys
):
    t, y = sine()
    path = tmp_path / 's.csv'
    np.savetxt(path, np.column_stack([t, y]), delimiter=',', header='t,torque', comments='')
    assert main(['analyze', str(path), '--model', 'biased-sinusoid']) == 0
    summary = summary_of(capsys.readouterr().err)
    assert 'damping not estimated' in summary[1]
    assert summary[3].endswith('-p damping_ratio:=0.0')
    (tmp_path / 'flat.csv').write_text('t,y\n' + ''.join(f'{i * 0.002},1.0\n' for i in range(500)))
    assert main(['analyze', str(tmp_path / 'flat.csv')]) == 0
    assert 'modes found:' not in capsys.readouterr().err


def test_shaper_rule_zvd_unless_the_spread_costs_it_more_than_ei_tolerance():
    def mode(spread):
        return ModeSummary(0, 10, 2.0, 0.0, spread, 0.01)

    zvd = design('zvd', 1.0, 0.01)
    for spread in (0.001, 0.05, 0.1, 0.15, 0.3):
        worst = np.max(sensitivity(zvd, [1 - spread, 1 + spread]))
        assert recommend_shaper(mode(spread)) == ('ei' if worst > EI_VTOL else 'zvd')
    assert recommend_shaper(mode(0.01)) == 'zvd' and recommend_shaper(mode(0.3)) == 'ei'
    stats = summarise_modes([1.0, 1.1, 3.0, 0.9], [0.01, 0.02, np.nan, 0.03], [1, 1, 2, 1])
    assert [(m.mode, m.count, m.frequency_hz) for m in stats] == [(1, 3, 1.0), (2, 1, 3.0)]
    assert stats[0].damping == 0.02 and np.isnan(stats[1].damping)
    # an estimate of the other mode labelled this one (before the tracker split them): counted
    # as an outlier, and it widens neither the std nor the spread the rule reads
    f = [1.0, 1.001, 0.999, 1.0005, 0.9995, 7.9]
    (m,) = summarise_modes(f, np.full(6, np.nan))
    assert m.outliers == 1 and m.frequency_std_hz < 0.002 and m.spread_rel < 0.004
    assert recommend_shaper(m) == 'zvd'


def test_fig1_has_a_title_units_and_the_truth(tmp_path):
    fig = reproduce._plot_fig1(reproduce.fig1(duration=0.3), str(tmp_path / 'fig1.png'))
    top, with_filter, without = fig.axes
    assert top.get_title().startswith('Fig. 1')
    assert top.get_ylabel() == 'y (dimensionless)'
    assert [a.get_ylabel() for a in (with_filter, without)] == ['omega (rad/s)'] * 2
    assert without.get_xlabel() == 't (s)'
    assert legend_texts(with_filter) == ['with invariant filtering', 'true omega = 10 rad/s']
    assert legend_texts(without) == ['without invariant filtering', 'true omega = 10 rad/s']


def test_fig2_plots_the_three_variants_of_its_table(tmp_path):
    zetas = np.linspace(0, 0.05, 4)
    results = [reproduce.fig2(zetas, **kw) for _, kw in reproduce.FIG2_VARIANTS]
    fig = reproduce._plot_fig2(results, str(tmp_path / 'fig2.png'))
    top, bottom = fig.axes
    names = [name for name, _ in reproduce.FIG2_VARIANTS]
    assert len(names) == 3
    assert [x.split(' (')[0] for x in legend_texts(top)] == names
    assert legend_texts(bottom)[:3] == legend_texts(top)
    assert top.get_title().startswith('Fig. 2')
    assert top.get_ylabel() == 'convergence time T* (periods)'
    assert bottom.get_xlabel() == 'zeta_n (damping ratio)'
    for line, r in zip(top.get_lines(), results):
        assert np.array_equal(line.get_ydata(), r.convergence_time, equal_nan=True)
    values = np.concatenate([line.get_ydata() for line in top.get_lines()])
    assert np.ptp(values[np.isfinite(values)]) > 0.1  # not one flat line


def fake_runs(t, f_true):
    """Every method's Run: the trackers a noisy output, the algebraic ones three estimates."""
    rng = np.random.default_rng(0)
    runs = {}
    for name in compare.METHODS:
        index = np.array([len(t) // 4, len(t) // 2, 3 * len(t) // 4])
        runs[name] = compare.Run(
            f_true * (1 + 0.05 * rng.standard_normal(len(t))),
            index,
            f_true[index],
            np.full(3, 100),
            t[index] - 0.3,
            0.0,
        )
    return runs


def test_compare_plot_styles_are_distinct_and_the_algebraic_estimates_on_top(tmp_path):
    case = compare.CASES[-1]
    t, y, f_true = case.record(0)
    fig = compare.plot_case(str(tmp_path / 'c.png'), case, (t, y, f_true), fake_runs(t, f_true))
    signal_ax, full, zoom = fig.axes
    assert signal_ax.get_ylabel() == f'signal ({case.unit})' and case.unit == 'dimensionless'
    assert legend_texts(full) == ['true f', *compare.METHODS]
    assert len(compare.METHODS) > 10
    for ax in (full, zoom):
        lines = {line.get_label(): line for line in ax.get_lines()}
        looks = {
            (line.get_color(), line.get_linestyle(), line.get_marker())
            for name, line in lines.items()
            if name in compare.METHODS
        }
        assert len(looks) == len(compare.METHODS)
        algebraic = [lines[n].get_zorder() for n in compare.ALGEBRAIC_CONFIGS]
        trackers = [
            line.get_zorder()
            for n, line in lines.items()
            if n in compare.METHODS and n not in compare.ALGEBRAIC_CONFIGS
        ]
        truth = max(c.get_zorder() for c in ax.collections)
        assert min(algebraic) > max(trackers) and min(algebraic) > truth


def test_sensitivity_plot_none_line_clears_the_frame(tmp_path):
    fig = sensitivity_cli.plot(str(tmp_path / 's.png'), 0.0)
    ax = fig.axes[0]
    assert legend_texts(ax) == list(SHAPERS)
    assert ax.get_ylabel() == 'residual vibration (%)'
    none = [line for line in ax.get_lines() if line.get_label() == 'none'][0]
    assert np.allclose(none.get_ydata(), 100)
    bottom, top = ax.get_ylim()
    assert top > 100 + 0.05 * (top - bottom)  # visible, not on the top spine
    for line in ax.get_lines():
        assert np.max(line.get_ydata()) < top


def test_ambient_plot_names_the_method_and_shows_the_std_not_a_flat_window(tmp_path):
    from vib_estimator.sim.frame import modal_record

    t, y = modal_record(120.0, 20.0, [(1.0, 0.02, 1.0)], np.ones((1, 1)), snr_db=20.0, seed=2)
    path = tmp_path / 'amb.csv'
    np.savetxt(path, np.column_stack([t, y[:, 0]]), delimiter=',', header='t,y', comments='')
    signal = open_signal(path)
    config = EstimatorConfig(excitation='ambient', ambient_window_s=40.0)
    run = estimate_signal(signal, config, keep_samples=True)
    fig = plot_run(str(tmp_path / 'c.png'), 'amb.csv', signal, run, None, config)
    est_ax, third = fig.axes[1], fig.axes[2]
    assert len(run.estimates) and 'algebraic estimates' not in legend_texts(est_ax)
    assert third.get_ylabel() == 'frequency std (Hz)'
    shown = np.concatenate([line.get_ydata() for line in third.get_lines()])
    assert np.allclose(np.sort(shown), np.sort(run.estimates.frequency_std_hz))


def test_a_record_without_estimate_says_why_on_its_panels(tmp_path):
    path = tmp_path / 'noise.csv'
    t = np.arange(3000) / 100
    noise = np.random.default_rng(0).standard_normal(3000)
    np.savetxt(path, np.column_stack([t, noise]), delimiter=',', header='t,y', comments='')
    signal = open_signal(path)
    run = estimate_signal(signal, EstimatorConfig(), keep_samples=True)
    assert len(run.estimates) == 0
    fig = plot_run(str(tmp_path / 'd.png'), 'noise.csv', signal, run, None, None, 'the reason')
    texts = [x.get_text() for x in fig.axes[1].texts]
    assert texts == ['no estimate: the reason'] and not legend_texts(fig.axes[1])


def test_a_schedule_of_three_frequencies_marks_each_segments_median(tmp_path):
    from vib_estimator.analysis.plotting import plot_estimates

    t = np.arange(0, 30, 0.01)
    est_t = np.arange(1, 30, 1.0)
    est_f = np.where(est_t < 10, 1.6, np.where(est_t < 20, 1.3, 1.1))
    truth = [(0, 10, 1.6), (10, 20, 1.3), (20, 30, 1.1)]
    fig = plot_estimates(
        str(tmp_path / 'e.png'), t, np.sin(t), est_t, est_f, np.ones_like(est_t), truth
    )
    marks = [x for x in legend_texts(fig.axes[3]) if x.startswith('f = ')]
    assert marks == ['f = 1.6 Hz', 'f = 1.3 Hz', 'f = 1.1 Hz']  # one per mass, in time order


def test_joint_plot_gives_each_mode_its_own_strip_so_close_modes_do_not_overlap(tmp_path):
    from vib_estimator.analysis.channels import joint_run, plot_shapes
    from vib_estimator.sim.frame import modal_record

    modes = [(1.24, 0.01, 1.0), (1.29, 0.01, 1.0)]  # the Heritage Court Tower's close pair
    shapes = np.array([[1.0, 0.2], [0.2, 1.0], [0.7, -0.7]])
    t, y = modal_record(200.0, 10.0, modes, shapes, snr_db=25.0, seed=3)
    config = EstimatorConfig(excitation='ambient', ambient_window_s=80.0)
    _, result = joint_run(t, y, ['a', 'b', 'c'], config)
    fig = plot_shapes(str(tmp_path / 's.png'), 'pair', result)
    strips = fig.axes[:2]
    assert [s.get_ylabel().split('\n')[0] for s in strips] == ['mode 1', 'mode 2']
    (lo1, hi1), (lo2, hi2) = (s.get_ylim() for s in strips)
    assert hi1 < 1.29 * 0.995 and lo2 > 1.24 * 1.005  # each strip holds its own mode only
