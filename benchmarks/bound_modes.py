# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The exact Cramer-Rao bound of a close pair of modes: how much data a 2 % first estimate needs.

The pair of ``bench_modes.py`` (10 and 13 Hz, 30 % apart, amplitudes 1 : 0.5, zeta = 0.003, white
noise at 30 dB SNR for the weaker mode, fs = 1 kHz), observed from the excitation over windows of
1.0-2.0 periods of the 10 Hz mode. Fisher information J^T J / sigma^2 of the sum of two damped
sinusoids with unknown amplitudes, phases, frequencies and (first block) dampings, or with the
dampings known (second block: the undamped refinement's situation); printed: the 1-sigma bound on
each frequency in %, median / 90th percentile over 400 random phase pairs.
Usage: ``python benchmarks/bound_modes.py``
"""

import math

import numpy as np

FS = 1000.0
FREQS, AMPS, ZETA = (10.0, 13.0), (1.0, 0.5), 0.003
SIGMA = AMPS[1] / math.sqrt(2) * 10 ** (-30 / 20)
WINDOWS = (1.0, 1.2, 1.3, 1.4, 1.5, 1.6, 1.8, 2.0)


def bound_percent(periods, phases, free_damping):
    """1-sigma bound of each mode's frequency (% of it) over ``periods`` of the lowest mode."""
    t = np.arange(int(round(periods * FS / FREQS[0]))) / FS
    cols = []
    for f, a, ph in zip(FREQS, AMPS, phases):
        w = 2 * math.pi * f
        env = np.exp(-ZETA * w * t)
        s, c = (
            np.sin(w * math.sqrt(1 - ZETA**2) * t + ph),
            np.cos(w * math.sqrt(1 - ZETA**2) * t + ph),
        )
        cols += [env * s, a * env * c, a * t * env * c]  # d/dA, d/dphase, d/dw
        if free_damping:
            cols.append(-a * t * env * s)  # d/dsigma
    jac = np.column_stack(cols)
    cov = np.linalg.inv(jac.T @ jac) * SIGMA**2
    k = 4 if free_damping else 3
    return [
        100 * math.sqrt(cov[i * k + 2, i * k + 2]) / (2 * math.pi * f) for i, f in enumerate(FREQS)
    ]


def main() -> None:
    phases = np.random.default_rng(0).uniform(0, 2 * math.pi, (400, 2))
    for free in (True, False):
        print(
            'dampings '
            + ('unknown' if free else 'known')
            + f': 1-sigma bound in %, median / p90 over {len(phases)} phase pairs'
        )
        print(f'{"periods":>8} {"10 Hz":>15} {"13 Hz":>15}')
        for periods in WINDOWS:
            b = np.array([bound_percent(periods, p, free) for p in phases])
            print(
                f'{periods:8.1f} '
                + ' '.join(
                    f'{np.median(b[:, i]):7.2f} / {np.percentile(b[:, i], 90):5.2f}'
                    for i in range(2)
                )
            )


if __name__ == '__main__':
    main()
