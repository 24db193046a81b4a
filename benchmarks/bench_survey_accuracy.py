# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``survey``'s per-recording frequency: bias and 95 % interval coverage on fleets of identical
days, the weighted summary (default) beside the former default (median, order-statistic interval)
in the same run.

    python benchmarks/bench_survey_accuracy.py [--days 40] [--seed 0] [--fleets arm,decay,ambient]

Fleets (every day of a fleet has the same true frequency; what changes is the noise, the phases
and, for the arm, nothing else):
- ``arm``: the days of ``make survey`` (``scripts/make_fleet.py``'s arm, 20 s of the Section 5.3
  experiment, zeta 0.004) with the nominal tip mass and noise; truth: Eq. 23's frequency;
- ``decay``: 60 s of three free decays (plucks at 0, 20, 40 s, random phase and amplitude) of a
  5 Hz mode, zeta 0.004, 30 dB at the pluck, 500 Hz;
- ``ambient``: 180 s of a white-noise-driven 5 Hz mode, zeta 1 %, 26 dB, 500 Hz, read with
  ``--excitation ambient`` (:func:`vib_estimator.sim.ambient.ambient_record`).
Each row: the model, the summary, the median over days of the relative error of the day's
frequency (its bias), its spread (half the 5-95 % range), the share of days whose 95 % interval
holds the truth (goal >= 95 %), and the median interval half-width; the damping likewise where
estimated.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace

import numpy as np

from vib_estimator.analysis.survey import SUMMARIES, summarise
from vib_estimator.core import EstimatorConfig, create_estimator
from vib_estimator.sim import arm_model
from vib_estimator.sim.ambient import ambient_record
from vib_estimator.sim.signals import plucked_decays

FS = 500.0
DECAY_F, DECAY_ZETA, DECAY_SNR_DB = 5.0, 0.004, 30.0
AMBIENT_F, AMBIENT_ZETA, AMBIENT_SNR_DB, AMBIENT_S = 5.0, 0.01, 26.0, 180.0


def arm_day(seed: int):
    """One ``make survey`` day of the nominal arm: (t, y, true f, true zeta)."""
    nominal = arm_model.ArmParameters()
    rec = arm_model.simulate(
        20.0, (arm_model.Move(0.0, 1.0, 1.0, nominal.tip_mass_kg),), nominal, seed=seed
    )
    return rec.t, rec.torque, float(rec.f_true[-1]), nominal.damping_ratio


def decay_day(seed: int):
    """Three free decays of a 5 Hz mode (module doc): (t, y, true f, true zeta)."""
    t, y = plucked_decays(seed, DECAY_F, DECAY_ZETA, DECAY_SNR_DB, rate_hz=FS)
    return t, y, DECAY_F, DECAY_ZETA


def ambient_day(seed: int):
    """A white-noise-driven 5 Hz mode (module doc): (t, y, true f, true zeta)."""
    t, y, _ = ambient_record(
        AMBIENT_S, FS, [(AMBIENT_F, AMBIENT_ZETA, 1.0)], AMBIENT_SNR_DB, seed=seed
    )
    return t, y, AMBIENT_F, AMBIENT_ZETA


FLEETS = {
    'arm': (arm_day, ('sinusoid', 'biased-sinusoid', 'damped-sinusoid'), 'free'),
    'decay': (decay_day, ('sinusoid', 'biased-sinusoid', 'damped-sinusoid'), 'free'),
    'ambient': (ambient_day, ('damped-sinusoid',), 'ambient'),
}


def measure(fleet: str, days: int, seed: int):
    """{(model, summary): (frequency rows, damping rows)}: per day (error, lo, hi) relative."""
    make, models, excitation = FLEETS[fleet]
    out = {}
    for d in range(days):
        t, y, f0, z0 = make(seed * 1000 + d)
        for model in models:
            config = replace(EstimatorConfig(), model=model, excitation=excitation)
            est = create_estimator(config).process(t, y)
            take = np.ones(len(est), dtype=bool)
            for summary in SUMMARIES:
                row = summarise(est, take, summary)
                freq, damp = out.setdefault((model, summary), ([], []))
                freq.append(
                    [
                        row[k] / f0 - 1
                        for k in ('frequency_hz', 'frequency_lo_hz', 'frequency_hi_hz')
                    ]
                )
                lo, hi = (row.get(k, np.nan) for k in ('damping_lo', 'damping_hi'))
                if summary == 'median':
                    lo = hi = np.nan
                damp.append([row['damping'] / z0 - 1, lo / z0 - 1, hi / z0 - 1])
    return {k: (np.array(f), np.array(z)) for k, (f, z) in out.items()}


def _line(x: np.ndarray) -> str:
    err, lo, hi = x.T
    if not np.isfinite(err).any():
        return f'{"-":>9} {"-":>9} {"-":>8} {"-":>9}'
    bias = np.nanmedian(err)
    spread = (np.nanpercentile(err, 95) - np.nanpercentile(err, 5)) / 2
    covered = np.mean((lo <= 0) & (hi >= 0))
    half = np.nanmedian((hi - lo) / 2) if np.isfinite(lo).any() else np.nan
    return f'{bias:+9.3%} {spread:9.3%} {covered:8.0%} {half:9.3%}'


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--days', type=int, default=40)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--fleets', default=','.join(FLEETS))
    args = parser.parse_args(argv)
    head = f'{"bias":>9} {"spread":>9} {"covered":>8} {"half-w":>9}'
    print(f'{"fleet":<8} {"model":<16} {"summary":<9} frequency: {head}   damping: {head}')
    for fleet in args.fleets.split(','):
        started = time.perf_counter()
        results = measure(fleet, args.days, args.seed)
        for (model, summary), (freq, damp) in results.items():
            print(
                f'{fleet:<8} {model:<16} {summary:<9}            {_line(freq)}            '
                f'{_line(damp)}'
            )
        print(
            f'  ({fleet}: {args.days} days, {time.perf_counter() - started:.0f} s)',
            file=sys.stderr,
        )
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
