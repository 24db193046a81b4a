#!/usr/bin/env python3
# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The study of docs/health.md from the rows of ``make survey-temperature``:

    python scripts/health_study.py out/fleet_temperature_survey.jsonl [--drop-day 130]

Learns baselines from the first N recordings (N = 20 ... 100) with the same code as ``survey``
(:func:`vib_estimator.analysis.health.learn_rows`, :func:`~.flag_learned`) and prints, per mode,
the false alarms on the undamaged days, the first alarmed damaged day and the share of damaged
days alarmed, at a 1 % stiffness loss (as simulated) and, semi-synthetically, at other sizes:
the damaged days' measured frequencies rescaled by ``sqrt((1 - d) / (1 - 0.01))`` (the
estimator's error does not depend on a shift this small), with the per-recording test alone
(``--sequential none``) and with the CUSUM beside it (the default).
"""

from __future__ import annotations

import argparse
import copy
import json
import math

import numpy as np

from vib_estimator.analysis import health
from vib_estimator.analysis.survey import row_shape

SIMULATED_DAMAGE = 0.01


def day_of(row) -> int:
    return int(row['recording'].rstrip('/').rsplit('_', 1)[1])


def load(path):
    rows = [json.loads(line) for line in open(path)]
    for row in rows:
        for key, value in row.items():
            if value is None:
                row[key] = math.nan
    return rows


def judge(rows, n, drop_day, damage, cusum, false_alarm=None):
    rows = copy.deepcopy(rows)
    scale = math.sqrt((1 - damage) / (1 - SIMULATED_DAMAGE))
    for row in rows:
        if day_of(row) >= drop_day and row['frequency_hz'] == row['frequency_hz']:
            row['frequency_hz'] *= scale
    covariates = sorted(
        k[len(health.COVARIATE_PREFIX) :] for k in rows[0] if k.startswith(health.COVARIATE_PREFIX)
    )
    base = health.learn_rows(rows, covariates, n, None, row_shape, false_alarm)
    health.flag_learned(rows, base, row_shape, false_alarm, cusum)
    out = []
    for mode in base.modes:
        mine = [r for r in rows if r.get('baseline_mode') == mode.mode]
        undamaged = [r for r in mine if day_of(r) < drop_day]
        damaged = [r for r in mine if day_of(r) >= drop_day]
        first = min((day_of(r) for r in damaged if r['alarm']), default=None)
        out.append(
            dict(
                mode=mode.mode,
                frequency_hz=mode.frequency_hz,
                s_rel=mode.residual_std_hz / mode.frequency_hz,
                false_alarms=sum(r['alarm'] for r in undamaged),
                undamaged=len(undamaged),
                delay=None if first is None else first - drop_day,
                detected=sum(r['alarm'] for r in damaged) / max(len(damaged), 1),
                limit=float(np.median([r['alarm_limit_rel'] for r in damaged] or [math.nan])),
            )
        )
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('rows')
    parser.add_argument('--drop-day', type=int, default=130)
    args = parser.parse_args(argv)
    rows = load(args.rows)
    print('training length (1 % stiffness loss, P = 0.001 per recording per mode):')
    print(' N  mode  s (%)  limit (%)  test   false alarms  delay (days)  damaged days alarmed')
    for n in (20, 40, 60, 80, 100):
        for cusum in (False, True):
            for r in judge(rows, n, args.drop_day, SIMULATED_DAMAGE, cusum):
                print(
                    f'{n:3d} {r["mode"]:4d} {100 * r["s_rel"]:6.3f} {100 * r["limit"]:9.3f}  '
                    f'{"+cusum" if cusum else "limit":6} '
                    f'{r["false_alarms"]:6d} of {r["undamaged"]:3d} {str(r["delay"]):>10} '
                    f'{100 * r["detected"]:12.0f} %'
                )
    print('damage size (N = 80; semi-synthetic below 1 %, see the module doc):')
    print(' damage  mode  test    false alarms  delay (days)  damaged days alarmed')
    for damage in (0.0025, 0.005, 0.01, 0.02):
        for cusum in (False, True):
            for r in judge(rows, 80, args.drop_day, damage, cusum):
                print(
                    f'{100 * damage:6.2f} % {r["mode"]:4d}  {"+cusum" if cusum else "limit":6} '
                    f'{r["false_alarms"]:6d} of {r["undamaged"]:3d} {str(r["delay"]):>10} '
                    f'{100 * r["detected"]:12.0f} %'
                )
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
