# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The demo's session and estimation table (vib_estimator.demo.session, .estimation): the domain
choice, the simulator's parameters, the Listener's pairing of estimates with resets through topics,
and the per-mass pass criterion. (The whole demo as processes: test/nodes/test_shaper_node.py.)"""

from __future__ import annotations

import argparse

import pytest

from vib_estimator.demo import run
from vib_estimator.demo.estimation import MAX_MEDIAN_ERROR_PCT, mass_g, summarise
from vib_estimator.demo.session import (
    DOMAINS,
    MAX_DOMAIN_ID,
    Listener,
    Record,
    demo_domain,
    domain_id,
    sim_params,
)
from vib_estimator.nodes.runner import spin_until
from vib_estimator.nodes.sim_node import SIM_TIME_ORIGIN_NS
from vib_estimator.sim.arm_model import MASSES_5_5, natural_frequency_hz

TRUTH = [(8.0 * i, 8.0 * (i + 1), natural_frequency_hz(m)) for i, m in enumerate(MASSES_5_5)]


def test_domain_choice():
    assert demo_domain(7, '12') == 7  # --domain-id first
    assert demo_domain(None, '12') == 12  # then ROS_DOMAIN_ID
    for env in (None, '', 'x', str(MAX_DOMAIN_ID + 1)):  # else one of DOMAINS, never 0
        assert demo_domain(None, env) in DOMAINS and 0 not in DOMAINS
    assert domain_id('0') == 0 and domain_id(str(MAX_DOMAIN_ID)) == MAX_DOMAIN_ID
    for bad in ('-1', str(MAX_DOMAIN_ID + 1), 'one'):
        with pytest.raises(argparse.ArgumentTypeError):
            domain_id(bad)


def test_sim_params_are_ros_arguments_of_sim_node():
    params = sim_params(10, 24, [0.0, 0.03, 8.0, 0.0455], 2)
    assert params == [
        'speed:=10.0',
        'duration:=24.0',
        'publish_clock:=true',
        'wait_for_subscribers:=2',
        'schedule:=[0.0, 0.03, 8.0, 0.0455]',
    ]


def test_mass_of_a_frequency_inverts_eq_23():
    for m in MASSES_5_5:
        assert mass_g(natural_frequency_hz(m)) == pytest.approx(m * 1e3, rel=1e-9)


def _record(errors_pct):
    """A Record with five estimates per mass, each mass's off by its error (%)."""
    rec = Record(TRUTH, heard_truth=[f for *_, f in TRUTH])
    for (t0, _, f0), err in zip(TRUTH, errors_pct):
        for k in range(5):
            rec.est_t.append(t0 + 1 + k)
            rec.est_f.append(f0 * (1 + err / 100))
            rec.est_conv.append(0.5)
    return rec


def test_summary_passes_only_when_every_mass_is_within_the_limit():
    rows, ok = summarise(_record([0.5, -1.0, 2.0]))
    assert ok and len(rows) == 1 + len(MASSES_5_5)
    assert [float(r.split()[3]) for r in rows[1:]] == pytest.approx([0.5, -1.0, 2.0], abs=0.01)
    assert not summarise(_record([0.5, -(MAX_MEDIAN_ERROR_PCT + 0.5), 0.0]))[1]
    rec = _record([0.0, 0.0])  # the last mass got no estimate
    rows, ok = summarise(rec)
    assert not ok and 'no estimate' in rows[-1]
    rec = _record([0.0, 0.0, 0.0])
    rec.heard_truth = rec.heard_truth[:1]
    assert summarise(rec)[0][-1].startswith('warning:')


def test_listener_pairs_each_frequency_with_its_reset(ros_context, executor):
    from geometry_msgs.msg import WrenchStamped
    from rclpy.node import Node
    from std_msgs.msg import Float64, Header

    listener = Listener(ros_context, TRUTH)
    executor.add_node(listener.node)
    talker = Node('demo_talker', context=ros_context)
    executor.add_node(talker)
    pubs = {
        topic: talker.create_publisher(kind, topic, 10)
        for topic, kind in (
            ('coupling_torque', WrenchStamped),
            ('vibration/frequency', Float64),
            ('vibration/reset', Header),
        )
    }
    assert spin_until(
        executor, lambda: all(p.get_subscription_count() for p in pubs.values()), 10.0
    )

    def header(seconds):
        ns = SIM_TIME_ORIGIN_NS + int(seconds * 1e9)
        msg = Header()
        msg.stamp.sec, msg.stamp.nanosec = divmod(ns, 10**9)
        return msg

    torque = WrenchStamped(header=header(0.25))
    torque.wrench.torque.z = 0.7
    pubs['coupling_torque'].publish(torque)
    for t, f in ((1.5, 1.2), (9.0, 1.05)):
        pubs['vibration/frequency'].publish(Float64(data=f))
        pubs['vibration/reset'].publish(header(t))
    rec = listener.record
    assert spin_until(executor, lambda: len(rec.est_t) == 2 and rec.t, 10.0)
    assert rec.t == pytest.approx([0.25]) and rec.torque == [0.7]
    assert rec.est_t == pytest.approx([1.5, 9.0]) and rec.est_f == [1.2, 1.05]
    assert rec.est_conv == pytest.approx([1.5, 7.5])  # since the start, then the last reset
    assert rec.truth_at(9.0) == TRUTH[1][2]


def test_bad_arguments_exit_2_before_any_node_starts(capsys):
    args = argparse.Namespace(speed=0.0, seconds_per_mass=8.0, shaping=False, step=0.5)
    assert run(args) == 2
    args = argparse.Namespace(speed=10.0, seconds_per_mass=4.0, shaping=True, step=0.5)
    assert run(args) == 2
    assert capsys.readouterr().err.count('error:') == 2
