#!/usr/bin/env python3
# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Simulate a fleet of daily recordings of the flexible arm, for ``vib-estimator survey``.

    python scripts/make_fleet.py [--out out/fleet] [--days 40] [--drop-day 30] [--seed 0]
                                 [--excitation free|ambient]

Day d is one rosbag2 bag (MCAP) ``<out>/day_DD``: 20 s of the Section 5.3 experiment
(:func:`vib_estimator.sim.arm_model.simulate`, a 1 rad ramp, then the free vibration) recorded at
the simulated sample times from midnight UTC of day d. Each day draws (seeded) its tip mass within
+-0.2 % of 45.55 g (payload tolerance) and its gauge noise between 0.5x and 2x the default; from
``--drop-day`` on the bar's stiffness is 1 % lower (a loosened clamp), so its frequency is ~0.5 %
lower (Eq. 23: f ~ sqrt(c)). The topic is ``/coupling_torque`` (``WrenchStamped``, ``torque.z``),
the only one, so ``survey`` reads it without ``--topic``. The output directory is replaced.

``--excitation ambient``: operational days instead (``make survey-ambient``): 180 s of a structure
under wind/traffic-like broadband forces, one white-noise-driven mode of 5 Hz, zeta 1 %, 26 dB
(:func:`vib_estimator.sim.ambient.ambient_record`); each day draws its frequency within +-0.1 %
(temperature) and its damping ratio within 0.8-1.25 %; from ``--drop-day`` on the mode drifts
down by :data:`AMBIENT_DRIFT` per day (a growing crack).
"""

from __future__ import annotations

import argparse
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np

from vib_estimator.io.bags import WrenchSeries, write_wrench_series
from vib_estimator.sim import arm_model
from vib_estimator.sim.ambient import ambient_record

EPOCH_NS = 1_767_225_600 * 1_000_000_000  # 2026-01-01 00:00:00 UTC, day 0
DAY_NS = 86_400 * 1_000_000_000
DURATION_S = 20.0
STIFFNESS_DROP = 0.01
AMBIENT_S, AMBIENT_FS, AMBIENT_F, AMBIENT_SNR_DB = 180.0, 500.0, 5.0, 26.0
AMBIENT_DRIFT = 0.002  # relative frequency lost per day from the drop day on


def day_recording(day: int, drop_day: int, rng: np.random.Generator) -> arm_model.Recording:
    """The simulated recording of one day (its mass, noise and stiffness as described above)."""
    nominal = arm_model.ArmParameters()
    mass = nominal.tip_mass_kg * (1 + 0.002 * rng.uniform(-1, 1))
    noise = arm_model.DEFAULT_NOISE_STD * rng.uniform(0.5, 2.0)
    stiffness = nominal.stiffness * (1 - STIFFNESS_DROP if day >= drop_day else 1.0)
    params = replace(nominal, stiffness=stiffness, tip_mass_kg=mass)
    return arm_model.simulate(
        DURATION_S,
        (arm_model.Move(0.0, 1.0, 1.0, mass),),
        params,
        noise_std=noise,
        seed=int(rng.integers(2**31)),
    )


def ambient_day(day: int, drop_day: int, rng: np.random.Generator):
    """``(t, y, f)``: the operational record of one day and its true frequency (module doc)."""
    f = (
        AMBIENT_F
        * (1 + 0.001 * rng.uniform(-1, 1))
        * (1 - AMBIENT_DRIFT * max(day - drop_day + 1, 0))
    )
    zeta = rng.uniform(0.008, 0.0125)
    t, y, _ = ambient_record(
        AMBIENT_S, AMBIENT_FS, [(f, zeta, 1.0)], AMBIENT_SNR_DB, seed=int(rng.integers(2**31))
    )
    return t, y, f


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--out', type=Path, default=Path('out/fleet'))
    parser.add_argument('--days', type=int, default=40)
    parser.add_argument('--drop-day', type=int, default=30)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--excitation', choices=('free', 'ambient'), default='free')
    args = parser.parse_args(argv)
    shutil.rmtree(args.out, ignore_errors=True)
    args.out.mkdir(parents=True)
    rng = np.random.default_rng(args.seed)
    for day in range(args.days):
        if args.excitation == 'ambient':
            t, y, f0 = ambient_day(day, args.drop_day, rng)
        else:
            rec = day_recording(day, args.drop_day, rng)
            t, y, f0 = rec.t, rec.torque, rec.f_true[-1]
        stamps = EPOCH_NS + day * DAY_NS + np.round(t * 1e9).astype(np.int64)
        write_wrench_series(
            args.out / f'day_{day:02d}', WrenchSeries(stamps, y, 'arm_base', '/coupling_torque')
        )
        print(f'{args.out / f"day_{day:02d}"}: f0 = {f0:.5f} Hz')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
