# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Issue 22's bad-input cases, before and after, in one run: the gap test and the outlier test
switched off (``gap_intervals`` = 0, ``outlier_ratio`` = 0: the previous behaviour) beside the
defaults.

1. Lost samples: a 2 Hz sine at 500 Hz with 40 gaps of 40-400 ms cut out (noise-free; each gap
   below ``max_gap``), 5 seeds per model: estimates published, how many > 5 % off, the worst error,
   and the gaps / samples lost counted.
2. One absurd sample: a damped 3 Hz sine (zeta 0.01, 500 Hz, 10 s) with one sample at 1e6 or 1e300
   (a value beyond 1e100 is skipped even with the tests off):
   estimates, worst error, non-finite numbers published, outliers counted.
"""

import numpy as np

from vib_estimator.core import EstimatorConfig, FrequencyEstimator
from vib_estimator.sim.signals import gappy_sine

FS, F0 = 500.0, 2.0
OFF = {'gap_intervals': 0.0, 'outlier_ratio': 0.0}


def row(label, est, e, truth):
    err = np.abs(e.frequency_hz / truth - 1)
    c = est.counters
    bad = sum(
        int(np.sum(~np.isfinite(getattr(e, k)))) for k in ('fit', 'amplitude', 'frequency_std_hz')
    )
    print(
        f'  {label:<34} {len(e):5d} {int(np.sum(err > 0.05)):5d} {np.max(err, initial=0):9.2e} '
        f'{bad:5d} {c["gaps"]:5d} {c["samples_lost"]:6d} {c["skipped_outlier"]:5d}'
    )


def main() -> None:
    head = (
        f'  {"case":<34} {"est":>5} {">5%":>5} {"worst":>9} {"inf":>5} {"gaps":>5} '
        f'{"lost":>6} {"outl":>5}'
    )
    print('1. 40 gaps of 40-400 ms in a 2 Hz sine at 500 Hz (lost samples per seed in brackets)')
    print(head)
    for model, offset in (('sinusoid', 0.0), ('biased-sinusoid', 0.3)):
        for seed in range(5):
            t, y, lost = gappy_sine(seed, offset)
            for name, extra in (('tests off', OFF), ('default', {})):
                est = FrequencyEstimator(EstimatorConfig(model=model, **extra))
                row(f'{model} seed {seed} [{lost}] {name}', est, est.process(t, y), F0)
    print('2. one absurd sample in a damped 3 Hz sine')
    print(head)
    t = np.arange(0, 10, 1 / FS)
    wn = 2 * np.pi * 3.0
    clean = np.exp(-0.01 * wn * t) * np.sin(wn * np.sqrt(1 - 1e-4) * t)
    for value in (1e6, 1e300):
        y = clean.copy()
        y[1234] = value
        for model in ('sinusoid', 'damped-sinusoid'):
            for name, extra in (('tests off', OFF), ('default', {})):
                est = FrequencyEstimator(EstimatorConfig(model=model, **extra))
                row(f'{model} {value:g} {name}', est, est.process(t, y), 3.0)


if __name__ == '__main__':
    main()
