# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Accuracy on real free-vibration recordings (not part of this project; read where they lie).

Runs ``vib-estimator analyze``'s core over the aluminium-cantilever (ADXL357) recordings in
``../shared/real-data`` (or the folder given as argument) and prints, per beam and configuration:
number of estimates, median relative error and 90th percentile of |error| against the reference
frequency of each file's own FFT (SOURCE.md), and median convergence time in periods.
Configurations: the paper's estimator as printed (sinusoid model, no prefilter), the
``biased-sinusoid`` model, the paper's model with a band-pass prefilter [f/2, 2 f], and the
``damped-sinusoid`` model with that prefilter (which also prints the median damping ratio, to
compare with the log-decrement values of SOURCE.md), all four the paper's configuration
(``EstimatorConfig.paper``) but for the change named, and last the package's defaults
(biased-sinusoid over 1.25 periods with the consistency gate, ``docs/real_arm.md``).
"""

import sys
from pathlib import Path

import numpy as np

from vib_estimator.core import EstimatorConfig, estimate
from vib_estimator.io.csv_reader import read_csv_series

#: reference first-mode frequencies (Hz): this file's own FFT, per SOURCE.md
REFERENCE = {30: 16.360, 40: 9.392, 50: 6.054, 60: 4.268}


def configs(f_ref):
    return {
        'paper (sinusoid)': EstimatorConfig.paper(),
        'biased-sinusoid': EstimatorConfig.paper(model='biased-sinusoid'),
        'sinusoid + band [f/2, 2f]': EstimatorConfig.paper(band_hz=(f_ref / 2, 2 * f_ref)),
        'damped + band [f/2, 2f]': EstimatorConfig.paper(
            model='damped-sinusoid', band_hz=(f_ref / 2, 2 * f_ref)
        ),
        'package defaults': EstimatorConfig(),
    }


def report(label, t, y, f_ref):
    for name, cfg in configs(f_ref).items():
        e = estimate(t, y, cfg)
        if len(e) == 0:
            print(f'{label:18} {name:28} no estimate')
            continue
        err = e.frequency_hz / f_ref - 1
        zeta = f'{np.median(e.damping):11.4f}' if cfg.model == 'damped-sinusoid' else ''
        print(
            f'{label:18} {name:28} {len(e):5d} {100 * np.median(err):+8.2f} % '
            f'{100 * np.percentile(np.abs(err), 90):8.2f} % '
            f'{np.median(e.convergence_time) * f_ref:14.2f} {zeta}'
        )


def main() -> int:
    root = Path(
        sys.argv[1]
        if len(sys.argv) > 1
        else Path(__file__).resolve().parents[2] / 'shared' / 'real-data'
    )
    folder = root / 'aluminium_cantilever_adxl357'
    if not folder.is_dir():
        print(f'no real data at {folder}; pass the real-data folder as argument')
        return 1
    print(
        f'{"recording":18} {"configuration":28} {"n":>5} {"median err":>10} '
        f'{"p90 |err|":>10} {"conv (periods)":>14} {"median zeta":>11}'
    )
    for length, f_ref in REFERENCE.items():
        s = read_csv_series(folder / f'{length}cm_uniform_1000Hz.csv')
        report(f'{length} cm, 1 kHz CSV', s.t, s.y, f_ref)
        raw = np.load(next(folder.glob(f'raw_{length}cm_*.npy')))
        report(f'{length} cm, raw ~3.9k', raw[0] - raw[0, 0], raw[1], f_ref)
    return 0


if __name__ == '__main__':
    sys.exit(main())
