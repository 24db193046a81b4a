# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The measurement behind ``vib-estimator demo --shaping`` (the vibration a move adds to a mode
still ringing), its pass criterion on an offline run of the arm, and
``python -m vib_estimator.control`` (the live demo: test/nodes/test_shaper_node.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vib_estimator.control.__main__ import main as sensitivity_main
from vib_estimator.control.residual import added_vibration, move_onset
from vib_estimator.control.shaping import StreamingShaper, design, none
from vib_estimator.demo import Record, ShapedMove, measure_moves, shaping_events, summarise_shaping
from vib_estimator.sim.arm_model import (
    MASSES_5_5,
    ArmParameters,
    ArmSimulator,
    Move,
    natural_frequency_hz,
)


def test_added_vibration_separates_the_old_vibration_from_the_new():
    rng = np.random.default_rng(0)
    f, zeta = 1.3, 0.004
    w = 2 * math.pi * f
    t = np.arange(0, 10, 0.002)
    old = 0.6 * np.exp(-zeta * w * t) * np.sin(w * t + 0.3)
    t_move, t_settled = 4.0, 4.5
    new = np.where(
        t >= t_move, 0.02 * np.exp(-zeta * w * (t - t_move)) * np.cos(w * (t - t_move) + 1.0), 0.0
    )
    y = old + new + np.where(t >= t_settled, 0.1, 0.0) + 0.004 * rng.standard_normal(len(t))
    y[(t >= t_move) & (t < t_settled)] = 5.0  # the move itself: not fitted
    fit = added_vibration(t, y, t_move, t_settled, 3.5, 5.0, 1.01 * f, 0.0)
    decay = math.exp(-zeta * w * (t_settled - t_move))
    assert fit.added == pytest.approx(0.02 * decay, rel=0.03)
    assert fit.previous == pytest.approx(0.6 * math.exp(-zeta * w * t_settled), rel=0.01)
    assert fit.frequency_hz == pytest.approx(f, rel=1e-4)
    assert fit.rms_residual == pytest.approx(0.004, rel=0.1)
    assert move_onset(t, y, 3.9, f, zeta) == pytest.approx(t_move, abs=0.003)
    with pytest.raises(ValueError):
        added_vibration(t, y, 0.0, 0.5, 0.0, 1.0, f)


def offline_run(error: float, shaper: str = 'zvd', seconds_per_mass: float = 6.0):
    """The demo's timeline on the arm model without ROS: the shaper designed for the true
    frequency times (1 + error), the 'estimates' recorded just before each shaped move."""
    sim = ArmSimulator(
        ArmParameters(tip_mass_kg=MASSES_5_5[0]),
        schedule=[Move(i * seconds_per_mass, 0.0, 1.0, m) for i, m in enumerate(MASSES_5_5)],
        seed=2,
    )
    events = shaping_events(seconds_per_mass, shaper, 0.5)
    truth = [
        (i * seconds_per_mass, (i + 1) * seconds_per_mass, natural_frequency_hz(m))
        for i, m in enumerate(MASSES_5_5)
    ]
    rec, moves = Record(truth), []
    stream, reference = StreamingShaper(none(), 500.0), 0.0
    for k in range(int(3 * seconds_per_mass * 500)):
        t = k / 500
        while events and events[0][0] <= t:
            _, kind, value = events.pop(0)
            f = rec.truth_at(t) * (1 + error)
            if kind == 'shaper':
                stream.request(design(value, f, 0.0))
                name = value
                if value != 'none':
                    rec.est_t.append(t)
                    rec.est_f.append(f)
            else:
                reference = value
                moves.append(ShapedMove(int(t // seconds_per_mass), t - 0.05, value, shaper=name))
        sim.set_command(stream.update(reference))
        ts, y, _ = sim.step()
        rec.t.append(ts)
        rec.torque.append(y)
    return rec, moves


def test_pass_criterion_on_an_offline_run():
    rec, moves = offline_run(0.01)
    rows = measure_moves(rec, moves, 6.0)
    lines, ok = summarise_shaping(rows, 'zvd')
    assert ok, '\n'.join(lines)
    assert all(r['ratio'] < 0.05 for r in rows) and len(lines) == 4
    assert all(r['unshaped'] > 0.5 for r in rows)  # 0.5 rad steps ring at ~0.77 N m
    # a shaper 35 % off leaves ~30 % of the vibration: the criterion fails
    rec, moves = offline_run(0.35)
    rows = measure_moves(rec, moves, 6.0)
    assert not summarise_shaping(rows, 'zvd')[1]
    assert all(r['ratio'] > 0.15 for r in rows)
    # ZV's own goal is <= 20 %; a missing mass fails
    assert summarise_shaping([dict(rows[0], ratio=0.15)] * 3, 'zv')[1]
    assert not summarise_shaping([dict(rows[0], ratio=0.15)] * 3, 'zvd')[1]
    assert not summarise_shaping([dict(rows[0], ratio=0.01)] * 2, 'zvd')[1]


def test_sensitivity_command(capsys, tmp_path):
    assert sensitivity_main(['--plot', str(tmp_path / 's.png')]) == 0
    rows = capsys.readouterr().out.splitlines()
    zv_row = next(r for r in rows if r.split()[0] == 'zv').split()
    assert float(zv_row[1]) == 0.5 and float(zv_row[4]) == pytest.approx(7.85, abs=0.01)
    assert (tmp_path / 's.png').stat().st_size > 10_000
    assert sensitivity_main(['--damping', '2']) == 2


def test_sped_up_demo_holds_the_simulator_at_each_event():
    """Sped up, the driver acts at each event's simulated time, whatever its own lag: the
    simulator holds there (``pause_at``) until the event is done and the next one's time is set;
    the last releases it. (The CI failure this answers: a listener 0.6 s behind made the last
    shaped move too late to measure.)"""
    from types import SimpleNamespace

    from vib_estimator.demo.shaping import drive

    events = shaping_events(6.0, 'zvd', 0.5)
    calls = []

    class Driver:
        heard = 0.0

        def now(self):
            return self.heard

        def set_shaper(self, name):
            calls.append(('shaper', self.heard, name))

        def move(self, reference):
            calls.append(('move', self.heard, reference))

        def pause_sim_at(self, t):
            calls.append(('pause_at', self.heard, t))
            self.heard = t or 99.0  # the simulator runs on to the hold (or to its end)

    def spin_until(predicate, timeout):
        return predicate()

    args = SimpleNamespace(seconds_per_mass=6.0, shaper='zvd', step=0.5, speed=10.0)
    sim = SimpleNamespace(poll=lambda: None)
    driver = Driver()
    driver.heard = events[0][0]  # sim_node started with pause_at at the first event
    moves = drive(SimpleNamespace(spin_until=spin_until), driver, sim, events, args, held=True)
    acted = [c for c in calls if c[0] != 'pause_at']
    assert [(kind, t, value) for t, kind, value in events] == acted  # each at its own time
    holds = [c[2] for c in calls if c[0] == 'pause_at']
    assert holds == [t for t, _, _ in events[1:]] + [0.0]
    assert [m.t for m in moves] == [t for t, kind, _ in events if kind == 'move']
