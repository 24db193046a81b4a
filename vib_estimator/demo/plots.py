# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The demos' figures: the estimation demo's (Fig. 5/7-like: the signal, the estimates against
Eq. 23, their convergence times) and the shaping demo's (what each move did, the estimates, the
shaper's impulses, the vibration each move added)."""

from __future__ import annotations

from typing import List

import numpy as np

from ..analysis.plotting import plot_estimates, pyplot
from .session import Record


def plot_estimation(path: str, rec: Record, speed: float) -> None:
    """The estimation demo's figure: the torque heard, each estimate against the schedule's
    Eq. 23 frequency and its convergence time."""
    plot_estimates(
        path,
        np.asarray(rec.t),
        np.asarray(rec.torque),
        np.asarray(rec.est_t),
        np.asarray(rec.est_f),
        np.asarray(rec.est_conv),
        rec.truth,
        title=f'Simulated arm, tip masses 30 / 45.55 / 61.17 g ({speed:g}x)',
        ylabel='coupling torque',
        unit='N·m',
    )


def plot_shaping(path: str, rec: Record, rows: List[dict], shaper: str, speed: float) -> None:
    """Per mass what the unshaped and the shaped move did to the torque (the signal minus the
    vibration continued from before the move, from the fit), then the estimates against Eq. 23,
    each shaped move's impulses, and the vibration each move added."""

    plt = pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(13, 7))
    t, y = np.asarray(rec.t), np.asarray(rec.torque)
    for ax, r in zip(axes[0], rows):
        for mv, fit, label, color in zip(
            r['moves'], r['fits'], ('unshaped', shaper), ('C0', 'C3')
        ):
            sel = (t >= mv.t - 0.5) & (t < mv.t + 3.0)
            ax.plot(
                t[sel] - mv.t,
                y[sel] - fit.continued(t[sel]),
                lw=0.7,
                color=color,
                label=f'{label} (adds {fit.added:.3f})',
            )
        ax.set_title(f'{r["mass_g"]:.2f} g, f0 {r["f0"]:.3f} Hz')
        ax.set_xlabel('time from the move (s)')
        ax.legend(loc='upper right', fontsize=8)
    axes[0][0].set_ylabel('torque minus the earlier vibration (N m)')
    axes[1][0].plot(rec.est_t, rec.est_f, '*', color='C3', label='estimates')
    for i, (t0, t1, f) in enumerate(rec.truth):
        axes[1][0].hlines(
            f, t0, t1, colors='k', linestyles='--', label='Eq. 23' if i == 0 else None
        )
    axes[1][0].set(xlabel='time (s)', ylabel='frequency (Hz)', ylim=(0.9, 2.0))
    axes[1][0].legend(fontsize=8)
    for i, r in enumerate(rows):
        s = r['moves'][1].shaper
        if s is not None:
            axes[1][1].stem(
                s.times,
                s.amplitudes,
                linefmt=f'C{i}-',
                markerfmt=f'C{i}o',
                basefmt=' ',
                label=f'{r["mass_g"]:.0f} g: {r["estimate"]:.3f} Hz',
            )
    axes[1][1].set(xlabel='impulse time (s)', ylabel='amplitude', title=f'{shaper} impulses')
    axes[1][1].legend(fontsize=8)
    x = np.arange(len(rows))
    axes[1][2].bar(x - 0.2, [r['unshaped'] for r in rows], 0.4, label='unshaped')
    axes[1][2].bar(x + 0.2, [r['shaped'] for r in rows], 0.4, label=shaper, color='C3')
    axes[1][2].set(
        xticks=x,
        xticklabels=[f'{r["mass_g"]:.0f} g' for r in rows],
        yscale='log',
        ylabel='vibration the move adds (N m)',
    )
    axes[1][2].legend(fontsize=8)
    fig.suptitle(f'Input shaping with the on-line estimate, simulated arm ({speed:g}x)')
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
