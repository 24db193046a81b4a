# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Precision against the exact Cramer-Rao bound, per model and window, beside a matrix pencil.

For each model (sinusoid; biased-sinusoid with an offset of 3 amplitudes; damped-sinusoid with
zeta = 0.01), each window (``min_periods`` = 0.25, 0.5, 1, 2, 5, 20 periods) and each SNR (20, 40,
60 dB; SNR = A^2 / (2 sigma^2)), the estimator (the paper's configuration,
``EstimatorConfig.paper``, but ``model`` and ``min_periods``) runs over seeded records of a 1.33 Hz
mode sampled at 2 ms (A = 0.1, random phase). Printed: the number of estimates, the RMS error of
the published frequencies, the exact bound (RMS over the estimates of
:func:`vib_estimator.analysis.bounds.model_crb` on the samples each used), the ratio RMS(error /
bound) over the estimates (the std in units of each estimate's own bound; the bound changes from
window to window), the calibration RMS of error / ``frequency_std_hz`` (1 = calibrated), the median
convergence time in periods, and a sliding matrix pencil
(:func:`vib_estimator.analysis.baselines.matrix_pencil`, damped-exponential model, order 2, +1
with an offset) on the same windows: its RMS(error / bound). Same run, same signals.

A last block, ``sinusoid+band``, runs the sinusoid with ``band_hz`` = [f/2, 2f]: the prefilter
colours the noise, so its std is the least-squares sandwich under the prefilter's noise
covariance, with the noise level from the window's residual, which is rough over windows short
against 1 / (f_hi - f_lo) = 0.5 s (``calib``, here, shows where). Its records start
``SETTLE`` s earlier and the estimates of windows that begin in that prefilter start-up are
dropped; its bound is the sinusoid's on the unfiltered white noise.
Usage: ``python benchmarks/bench_precision.py [--quick]`` (--quick: 0.5, 2 and 20 periods, 40 dB).
"""

import math
import sys
import time

import numpy as np

from vib_estimator.analysis.baselines import matrix_pencil
from vib_estimator.analysis.bounds import model_crb
from vib_estimator.core import EstimatorConfig, FrequencyEstimator

F0, AMP, TS = 1.33, 0.1, 0.002
#: label: (model, zeta, offset, band_hz)
CASES = {
    'sinusoid': ('sinusoid', 0.0, 0.0, None),
    'biased-sinusoid': ('biased-sinusoid', 0.0, 0.3, None),
    'damped-sinusoid': ('damped-sinusoid', 0.01, 0.0, None),
    'sinusoid+band': ('sinusoid', 0.0, 0.0, (F0 / 2, 2 * F0)),
}
#: the band prefilter's start-up: windows beginning earlier are not scored (s)
SETTLE = 3.0


def records(zeta, offset, sd, periods, seed, lead=0.0):
    """Seeded records, each 4 windows (at least 6 s) long: a damped mode decays, so many short
    records; enough of them for >= ~120 estimates per cell (an RMS over n estimates has a
    relative sampling error of ~1/sqrt(2 n): 6.5 % at 120)."""
    rng = np.random.default_rng(seed)
    n_rec = 40 if periods < 5 else 36
    for _ in range(n_rec):
        t = np.arange(0.0, lead + max(6.0, 4 * periods / F0), TS)
        phase = rng.uniform(0, 2 * math.pi)
        wn = 2 * math.pi * F0
        sig = zeta * wn
        y = AMP * np.exp(-sig * t) * np.sin(math.sqrt(wn * wn - sig * sig) * t + phase) + offset
        yield t, y + rng.normal(0.0, sd, len(t)), phase, zeta


def cell(model, zeta, offset, band, snr_db, periods):
    sd = AMP / math.sqrt(2 * 10 ** (snr_db / 10))
    cfg = EstimatorConfig.paper(model=model, min_periods=periods, band_hz=band)
    lead = SETTLE if band else 0.0
    err, bound, z, per, mp, norm, mpn = [], [], [], [], [], [], []
    for t, y, phase, zeta in records(zeta, offset, sd, periods, int(periods * 100 + snr_db), lead):
        e = FrequencyEstimator(cfg).process(t, y)
        for k in range(len(e)):
            i1 = int(round(e.t[k] / TS))
            n = int(e.samples[k])
            if t[i1 - n + 1] < lead:
                continue
            tw = t[i1 - n + 1 : i1 + 1]
            # the mode's amplitude and phase at t = 0 of the record: the bound on the window
            b, _ = model_crb(model, tw, AMP, F0, phase, sd, zeta)
            err.append(e.frequency_hz[k] - F0)
            bound.append(b)
            norm.append((e.frequency_hz[k] - F0) / b)
            z.append((e.frequency_hz[k] - F0) / e.frequency_std_hz[k])
            per.append(e.convergence_time[k] * F0)
            mp.append(matrix_pencil(y[i1 - n + 1 : i1 + 1], TS, 3 if offset else 2)[0] - F0)
            mpn.append(mp[-1] / b)
    if not err:
        return None
    rms = lambda v: math.sqrt(np.nanmean(np.square(v)))  # noqa: E731
    return len(err), rms(err), rms(bound), rms(norm), rms(z), np.median(per), rms(mpn)


def main() -> None:
    quick = '--quick' in sys.argv
    windows = (0.5, 2, 20) if quick else (0.25, 0.5, 1, 2, 5, 20)
    snrs = (40,) if quick else (20, 40, 60)
    print(
        f'{"model":>16} {"periods":>7} {"SNR":>4} {"n":>5} {"std Hz":>9} {"bound Hz":>9} '
        f'{"ratio":>6} {"calib":>6} {"+-":>5} {"conv":>6} {"pencil":>7}'
        '   (ratio, pencil: RMS error/bound; +-: sampling error of an RMS over n)'
    )
    start = time.perf_counter()
    for label, (model, zeta, offset, band) in CASES.items():
        for periods in windows:
            for snr in snrs:
                r = cell(model, zeta, offset, band, snr, periods)
                if r is None:
                    print(f'{label:>16} {periods:7} {snr:4}   no estimate')
                    continue
                n, std, bound, ratio, calib, conv, mp = r
                print(
                    f'{label:>16} {periods:7} {snr:4} {n:5} {std:9.2e} {bound:9.2e} '
                    f'{ratio:6.2f} {calib:6.2f} {1 / math.sqrt(2 * n):5.2f} {conv:6.2f} '
                    f'{mp:7.2f}',
                    flush=True,
                )
    print(f'({time.perf_counter() - start:.0f} s)')


if __name__ == '__main__':
    main()
