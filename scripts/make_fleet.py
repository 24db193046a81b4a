#!/usr/bin/env python3
# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Simulate a fleet of daily recordings of the flexible arm, for ``vib-estimator survey``.

    python scripts/make_fleet.py [--out out/fleet] [--days 40] [--drop-day 30] [--seed 0]
                                 [--excitation free|ambient] [--temperature]

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

``--temperature``: a two-mode structure under ambient excitation whose frequencies follow the
temperature (``make survey-temperature``, docs/health.md): 160 days (``--days``) of 300 s at
100 Hz, ``/accel`` (``sensor_msgs/Imu``, ``linear_acceleration.z``: modes of 8 and 21 Hz, zeta 1 %,
26 dB) and ``/temperature`` (``sensor_msgs/Temperature`` at 1 Hz, sensor noise 0.1 degC). The day's
temperature is a seasonal swing of +-10 degC (a year's sine, day 0 the coldest,
:data:`SEASON_DAYS`) plus a daily noise of 2 degC std; the modes follow it by -0.20 and
-0.15 %/degC (:data:`TEMPERATURE_COEF`) plus an unexplained 0.02 % a day; from ``--drop-day``
(default 130) the stiffness is ``--damage`` (default 1 %) lower, so both frequencies fall by
about half of it.
"""

from __future__ import annotations

import argparse
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np

from vib_estimator.io.bags import (
    BagWriter,
    WrenchSeries,
    channels_message,
    write_wrench_series,
    zero_message,
)
from vib_estimator.sim import arm_model
from vib_estimator.sim.ambient import ambient_record

EPOCH_NS = 1_767_225_600 * 1_000_000_000  # 2026-01-01 00:00:00 UTC, day 0
DAY_NS = 86_400 * 1_000_000_000
DURATION_S = 20.0
STIFFNESS_DROP = 0.01
AMBIENT_S, AMBIENT_FS, AMBIENT_F, AMBIENT_SNR_DB = 180.0, 500.0, 5.0, 26.0
AMBIENT_DRIFT = 0.002  # relative frequency lost per day from the drop day on
#: --temperature: the modes (Hz, damping ratio, variance), record, season and coefficients
TEMPERATURE_MODES = ((8.0, 0.01, 1.0), (21.0, 0.01, 0.5))
TEMPERATURE_S, TEMPERATURE_FS = 300.0, 100.0
SEASON_DAYS, SEASON_DEGC, DAILY_DEGC, SENSOR_DEGC = 365.0, 10.0, 2.0, 0.1
TEMPERATURE_COEF = (-0.0020, -0.0015)  # relative frequency change per degC, per mode
UNEXPLAINED = 0.0002  # relative day-to-day frequency scatter the temperature does not explain


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


def temperature_day(day: int, drop_day: int, damage: float, rng: np.random.Generator):
    """``(t, y, temperatures, frequencies)``: one day of the temperature fleet (module doc)."""
    celsius = -SEASON_DEGC * np.cos(2 * np.pi * day / SEASON_DAYS) + DAILY_DEGC * rng.normal()
    stiffness = 1 - damage if day >= drop_day else 1.0
    modes = [
        (f * (1 + c * celsius) * (1 + UNEXPLAINED * rng.normal()) * np.sqrt(stiffness), z, v)
        for (f, z, v), c in zip(TEMPERATURE_MODES, TEMPERATURE_COEF)
    ]
    t, y, _ = ambient_record(
        TEMPERATURE_S, TEMPERATURE_FS, modes, AMBIENT_SNR_DB, seed=int(rng.integers(2**31))
    )
    n = int(TEMPERATURE_S)
    temperatures = celsius + 0.2 * np.linspace(-1, 1, n) + SENSOR_DEGC * rng.normal(size=n)
    return t, y, temperatures, [f for f, _, _ in modes]


def write_temperature_day(path: Path, stamps: np.ndarray, y: np.ndarray, temperatures) -> None:
    """A bag of ``/accel`` (Imu) and ``/temperature`` (Temperature, one a second), in log-time
    order."""
    imu, kind = 'sensor_msgs/msg/Imu', 'sensor_msgs/msg/Temperature'
    every = len(stamps) // len(temperatures)
    with BagWriter(path) as bag:
        accel, temp = bag.add_topic('/accel', imu), bag.add_topic('/temperature', kind)
        for i, (stamp, value) in enumerate(zip(stamps.tolist(), y.tolist())):
            bag.write_message(
                accel,
                stamp,
                channels_message(imu, stamp, 'base', ['linear_acceleration.z'], [value]),
            )
            if i % every == 0 and i // every < len(temperatures):
                msg = zero_message(kind)
                msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp, 1_000_000_000)
                msg.header.frame_id = 'base'
                msg.temperature = float(temperatures[i // every])
                msg.variance = SENSOR_DEGC**2
                bag.write_message(temp, stamp, msg)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--out', type=Path, default=Path('out/fleet'))
    parser.add_argument('--days', type=int, help='default 40; --temperature 160')
    parser.add_argument('--drop-day', type=int, help='default 30; --temperature 130')
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--excitation', choices=('free', 'ambient'), default='free')
    parser.add_argument(
        '--temperature', action='store_true', help='the two-mode temperature fleet (module doc)'
    )
    parser.add_argument('--damage', type=float, default=0.01, help='--temperature: stiffness loss')
    args = parser.parse_args(argv)
    if args.days is None:
        args.days = 160 if args.temperature else 40
    if args.drop_day is None:
        args.drop_day = 130 if args.temperature else 30
    shutil.rmtree(args.out, ignore_errors=True)
    args.out.mkdir(parents=True)
    rng = np.random.default_rng(args.seed)
    for day in range(args.days):
        if args.temperature:
            t, y, celsius, freqs = temperature_day(day, args.drop_day, args.damage, rng)
            stamps = EPOCH_NS + day * DAY_NS + np.round(t * 1e9).astype(np.int64)
            name = args.out / f'day_{day:03d}'
            write_temperature_day(name, stamps, y, celsius)
            print(f'{name}: {np.mean(celsius):+.2f} degC, f = {freqs[0]:.5f} {freqs[1]:.5f} Hz')
            continue
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
