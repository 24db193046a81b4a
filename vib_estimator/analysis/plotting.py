"""Figures in the style of the paper's Fig. 5 (signal / estimates / convergence times).

matplotlib is imported lazily with the non-interactive Agg backend, so nodes and the core never pay
for it and no display is needed.
"""
from __future__ import annotations

from typing import Optional, Sequence, Tuple

import numpy as np


def pyplot():
    """matplotlib.pyplot on the Agg backend."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    return plt


def plot_estimates(path: str, t: np.ndarray, y: np.ndarray, est_t: np.ndarray,
                   est_f: np.ndarray, est_conv: np.ndarray,
                   truth: Optional[Sequence[Tuple[float, float, float]]] = None,
                   title: str = '', ylabel: str = 'signal',
                   mode: Optional[np.ndarray] = None) -> None:
    """Write a three-panel PNG like Fig. 5.

    ``truth`` is a list of (t_start, t_end, f_true) segments drawn dashed in the middle panel.
    ``mode`` (the estimates' mode column, ``modes`` >= 1) colours the estimates by mode, with a
    legend "mode k"; without it (or all 0) they are one series.
    """
    plt = pyplot()
    fig, axes = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True)
    axes[0].plot(t, y, lw=0.7)
    axes[0].set_ylabel(ylabel)
    est_t, est_f, est_conv = (np.asarray(a) for a in (est_t, est_f, est_conv))
    mode = np.zeros(len(est_t), dtype=int) if mode is None else np.asarray(mode)
    for k in np.unique(mode) if len(mode) else [0]:
        sel = mode == k
        label, colour = ('algebraic estimates', 'C3') if k == 0 else (f'mode {k}', f'C{k - 1}')
        axes[1].plot(est_t[sel], est_f[sel], '*', color=colour, label=label)
        axes[2].plot(est_t[sel], est_conv[sel], 'o', mfc='none', color=colour)
    for i, (t0, t1, f) in enumerate(truth or []):
        axes[1].hlines(f, t0, t1, colors='k', linestyles='--',
                       label='true frequency' if i == 0 else None)
    axes[1].set_ylabel('frequency (Hz)')
    if len(np.unique(mode)) > 1:
        axes[1].set_yscale('log')          # modes a decade apart, each visible
    elif len(est_f):
        lo, hi = np.percentile(est_f, [2, 98])
        pad = max(0.05 * (hi - lo), 0.02 * hi)
        axes[1].set_ylim(lo - pad, hi + pad)
    axes[1].legend(loc='best')
    axes[2].set_ylabel('convergence time (s)')
    axes[2].set_xlabel('time (s)')
    if title:
        axes[0].set_title(title)
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
