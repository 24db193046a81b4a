# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""A periodic motion: the simulated arm (Eqs. 19-23, 1.3306 Hz) moved back and forth without
rest, ramps one after another (a pick-and-place cycle; the last two schedules ramp without a
hold: the hub's angle a triangle wave), 300 s at 500 Hz, its coupling torque;
``vib-estimator analyze FILE`` with no option and with ``--excitation ambient``, in the same run.
Per schedule and configuration, over two seeds: estimates, the share within 2 % of the mode,
those beyond 5 %, and the frequencies the estimates beyond 5 % sit at (the move cycle's odd
harmonics: docs/known_limits.md, *A periodic motion*).

    cd benchmarks && ../.venv/bin/python bench_periodic.py
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
from bench_defaults import run

from vib_estimator.sim.arm_model import back_and_forth

#: (name, seconds a move, its angle (rad, alternately + and -), its ramp's slope (rad/s),
#: relative jitter of the angle and of the time between moves)
SCHEDULES = (
    ('2 s a move, 0.5 rad', 2.0, 0.5, 1.0, 0.0),
    ('1.5 s a move, jittered 50 %', 1.5, 0.5, 1.0, 0.5),
    ('4 s a move, 1 rad', 4.0, 1.0, 1.0, 0.0),
    ('0.8 s a move, 0.3 rad', 0.8, 0.3, 1.0, 0.0),
    ('ramps back to back, 1 s, 1 rad', 1.0, 0.5, 1.0, 0.0),
    ('ramps back to back, 2 s, 2 rad', 2.0, 1.0, 1.0, 0.0),
)


def record(seed: int, every: float, angle: float, slope: float, jitter: float, seconds=300.0):
    """``(t, torque, f)``: the arm moved every ``every`` s to +-``angle`` rad
    (:func:`vib_estimator.sim.arm_model.back_and_forth`)."""
    rec = back_and_forth(seconds, every, angle, slope, jitter, seed)
    return rec.t, rec.torque, float(rec.f_true[0])


def main() -> int:
    folder = Path(tempfile.mkdtemp())
    print(
        '| schedule | configuration | estimates | within 2 % | > 5 % | where the > 5 % sit (Hz) |'
    )
    print('|---|---|---|---|---|---|')
    for name, every, angle, slope, jitter in SCHEDULES:
        rows = {'default (no option)': [], '--excitation ambient': []}
        for seed in range(2):
            t, y, f = record(seed, every, angle, slope, jitter)
            path = folder / f'periodic_{seed}.csv'
            np.savetxt(
                path, np.column_stack([t, y]), delimiter=',', header='time_s,torque', comments=''
            )
            for label, args in zip(rows, ([], ['--excitation', 'ambient'])):
                rows[label] += [r['frequency_hz'] for r in run(path, args)[1]]
        for label, freqs in rows.items():
            freqs = np.array(freqs)
            err = np.abs(freqs / f - 1)
            off = sorted({round(float(v), 2) for v in freqs[err > 0.05]})
            where = ', '.join(f'{v:g}' for v in off[:6]) + (' ...' if len(off) > 6 else '')
            print(
                f'| {name} | {label} | {len(freqs)} | '
                f'{100 * np.mean(err <= 0.02) if len(freqs) else 0:.1f} % | '
                f'{int(np.sum(err > 0.05))} | {where or "-"} |',
                flush=True,
            )
    return 0


if __name__ == '__main__':
    sys.exit(main())
