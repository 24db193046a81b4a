# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The exact Cramer-Rao bound of a close pair of modes: how much data a 2 % first estimate needs.

The pair of ``bench_modes.py`` (10 and 13 Hz, 30 % apart, amplitudes 1 : 0.5, zeta = 0.003, white
noise at 30 dB SNR for the weaker mode, fs = 1 kHz), observed from the excitation over windows of
1.0-2.0 periods of the 10 Hz mode. Fisher information J^T J / sigma^2 of the sum of two damped
sinusoids with unknown amplitudes, phases, frequencies and (first block) dampings, or with the
dampings known (second block: the undamped refinement's situation); printed: the 1-sigma bound on
each frequency in %, median / 90th percentile over 400 random phase pairs.
Then, per mode of ``bench_modes.py``'s default cases (section 5), the shortest window from the
excitation whose bound allows 2 % at 3 sigma (``per_mode``): what the physics allows each mode.
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


def bound_window(freqs, amps, zetas, sigma, n, phases, free_damping):
    """1-sigma bound of each mode's frequency (relative) from ``n`` samples at FS after the
    excitation: the sum of damped sinusoids ``freqs, amps, zetas`` with ``phases``, an offset,
    white noise ``sigma``; amplitudes, phases, frequencies (and ``free_damping``: dampings)
    unknown."""
    t = np.arange(n) / FS
    cols, at = [np.ones(n)], []
    for f, a, z, ph in zip(freqs, amps, zetas, phases):
        w = 2 * math.pi * f
        env = np.exp(-z * w * t)
        s, c = np.sin(w * t + ph), np.cos(w * t + ph)
        at.append(len(cols) + 2)
        cols += [env * s, a * env * c, a * t * env * c]
        if free_damping:
            cols.append(-a * t * env * s)
    jac = np.column_stack(cols)
    cov = np.linalg.pinv(jac.T @ jac) * sigma**2
    return [math.sqrt(max(cov[i, i], 0.0)) / (2 * math.pi * f) for i, f in zip(at, freqs)]


#: the precision a mode's estimate needs: 2 % at 3 sigma
NEEDED = 0.02 / 3


def per_mode(phase_sets=40) -> None:
    """bench_modes.py's default cases: per mode, the shortest window from the excitation (in its
    own periods, steps of 0.1) whose bound is :data:`NEEDED` or less (median over random phases),
    with the dampings unknown (the tracker's fits) and known."""
    from bench_modes import DEFAULT_CASES  # benchmarks/ is the script's folder

    rng = np.random.default_rng(1)
    print(
        f'\nper mode: the shortest window (own periods) whose 1-sigma bound is <= '
        f'{100 * NEEDED:.2f} % (2 % at 3 sigma), median over {phase_sets} phase sets'
    )
    print('| case | mode Hz | dampings unknown | dampings known |')
    print('|---|---|---|---|')
    for name, (freqs, amps, zetas, snr) in DEFAULT_CASES.items():
        sigma = min(amps) / math.sqrt(2) * 10 ** (-snr / 20)
        phases = rng.uniform(0, 2 * math.pi, (phase_sets, len(freqs)))
        for k, f in enumerate(freqs):
            cells = []
            for free in (True, False):
                need = '> 6'
                for periods in np.arange(0.5, 6.01, 0.1):
                    n = int(round(periods * FS / f))
                    if n <= 4 * len(freqs) + 1:
                        continue
                    b = [bound_window(freqs, amps, zetas, sigma, n, p, free)[k] for p in phases]
                    if np.median(b) <= NEEDED:
                        need = f'{periods:.1f}'
                        break
                cells.append(need)
            print(f'| {name if k == 0 else ""} | {f:g} | {cells[0]} | {cells[1]} |')


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
    per_mode()


if __name__ == '__main__':
    main()
