# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Figures in the style of the paper's Fig. 5 (signal / estimates / convergence times), and the
signal's spectrum with the estimated modes marked.

matplotlib is imported lazily with the non-interactive Agg backend, so nodes and the core never pay
for it and no display is needed.
"""

from __future__ import annotations

import math
import textwrap
from typing import Optional, Sequence, Tuple

import numpy as np

from ..core.choice import regular
from ..io.fields import UNKNOWN_UNIT
from .summary import renumber, summarise_modes

#: the spectrum's segments resolve the lowest mode's frequency / this
PSD_RESOLUTION = 8.0
#: shortest Welch segment, samples
PSD_MIN_SEGMENT = 256
#: the spectrum's axis spans 0 .. this x the highest mode's frequency (or Nyquist)
PSD_SPAN = 4.0


def pyplot():
    """matplotlib.pyplot on the Agg backend."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, axes, path: str):
    """Grid every axis, lay the figure out, write it (110 dpi), close it; returns ``fig``."""
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    pyplot().close(fig)
    return fig


def mode_colour(k: int) -> str:
    """The colour of mode ``k`` (0: the single-mode estimator) in every panel."""
    return 'C3' if k == 0 else f'C{(k - 1) % 10}'


def plot_estimates(
    path: str,
    t: np.ndarray,
    y: np.ndarray,
    est_t: np.ndarray,
    est_f: np.ndarray,
    est_conv: np.ndarray,
    truth: Optional[Sequence[Tuple[float, float, float]]] = None,
    title: str = '',
    ylabel: str = 'signal',
    mode: Optional[np.ndarray] = None,
    unit: str = UNKNOWN_UNIT,
    label: str = 'algebraic estimates',
    panel3: Optional[Tuple[str, np.ndarray]] = None,
    note: str = '',
):
    """Write a four-panel PNG: the three panels of Fig. 5 and the signal's spectrum; return the
    Figure (closed: for inspection, not display).

    ``truth`` is a list of (t_start, t_end, f_true) segments drawn dashed in the middle panel.
    ``mode`` (the estimates' mode column, ``modes`` >= 1) colours the estimates by mode, with a
    legend "mode k"; without it (or all 0) they are one series. ``unit`` labels the signal axis
    (and the PSD's). The spectrum (:func:`welch_psd`) marks each mode's median estimate with a
    vertical line labelled "f = ... Hz" -- with ``truth``, each segment's median (a schedule's
    segments are different frequencies: one median across them would be none of them).
    ``label``: the single series' legend (what estimated them); ``panel3``: (y label, values) to
    draw instead of the convergence times (ambient: the window is the same for every estimate);
    ``note``: written on the empty estimate panels when there is no estimate (why).
    """
    plt = pyplot()
    fig = plt.figure(figsize=(9, 10))
    grid = fig.add_gridspec(4, 1, height_ratios=(1, 1, 1, 1.2))
    axes = [fig.add_subplot(grid[0])]
    axes += [fig.add_subplot(grid[i], sharex=axes[0]) for i in (1, 2)]
    ax_psd = fig.add_subplot(grid[3])
    axes[0].plot(t, y, lw=0.7)
    axes[0].set_ylabel(f'{ylabel} ({unit})')
    est_t, est_f, est_conv = (np.asarray(a) for a in (est_t, est_f, est_conv))
    mode = np.zeros(len(est_t), dtype=int) if mode is None else np.asarray(mode)
    for k in np.unique(mode) if len(mode) else [0]:
        sel = mode == k
        name = label if k == 0 else f'mode {k}'
        third = est_conv if panel3 is None else np.asarray(panel3[1])
        axes[1].plot(est_t[sel], est_f[sel], '*', color=mode_colour(k), label=name)
        axes[2].plot(est_t[sel], third[sel], 'o', mfc='none', color=mode_colour(k))
    for i, (t0, t1, f) in enumerate(truth or []):
        axes[1].hlines(
            f, t0, t1, colors='k', linestyles='--', label='true frequency' if i == 0 else None
        )
    axes[1].set_ylabel('frequency (Hz)')
    if len(np.unique(mode)) > 1:
        axes[1].set_yscale('log')  # modes a decade apart, each visible
    elif len(est_f):
        lo, hi = np.percentile(est_f, [2, 98])
        pad = max(0.05 * (hi - lo), 0.02 * hi)
        axes[1].set_ylim(lo - pad, hi + pad)
    if len(est_t) == 0:
        text = textwrap.fill('no estimate' + (f': {note}' if note else ''), 90)
        for ax, words in zip(axes[1:], (text, 'no estimate')):
            ax.text(0.5, 0.5, words, transform=ax.transAxes, ha='center', va='center', fontsize=9)
    else:
        axes[1].legend(loc='best')
    axes[2].set_ylabel('convergence time (s)' if panel3 is None else panel3[0])
    axes[2].set_xlabel('time (s)')
    if title:
        axes[0].set_title(title)
    if mode is not None:  # by identity, as the summary numbers them
        mode = renumber(est_f, mode, est_t)
    modes = summarise_modes(est_f, np.full(len(est_f), np.nan), mode)
    if truth:
        modes = segment_medians(est_t, est_f, truth)
    plot_spectrum(ax_psd, t, y, modes, unit)
    return save_figure(fig, (*axes, ax_psd), path)


def segment_medians(est_t, est_f, truth) -> list:
    """One :class:`.summary.ModeSummary` per ``truth`` segment (t0, t1, f) that holds estimates:
    their median."""
    out = []
    for t0, t1, _ in truth:
        sel = (est_t >= t0) & (est_t < t1) & np.isfinite(est_f)
        if sel.any():
            out += summarise_modes(est_f[sel], np.full(int(sel.sum()), np.nan))
    return out


def welch_psd(t: np.ndarray, y: np.ndarray, lowest_hz: float = math.nan):
    """One-sided Welch PSD (scipy.signal.welch, Hann, 50 % overlap) of ``y`` sampled at the median
    interval of ``t`` (irregular stamps: on a uniform grid, :func:`..core.choice.regular`):
    (frequencies in Hz, PSD in unit^2/Hz). The segments are long enough to resolve ``lowest_hz``
    / :data:`PSD_RESOLUTION` when given, else a quarter of the record."""
    from scipy.signal import welch

    t, y = regular(np.asarray(t, dtype=float), np.asarray(y, dtype=float))
    fs = 1.0 / float(np.median(np.diff(t)))
    want = PSD_RESOLUTION * fs / lowest_hz if lowest_hz > 0 else len(y) / 4
    nperseg = int(min(len(y), max(PSD_MIN_SEGMENT, want)))
    return welch(y - np.mean(y), fs=fs, nperseg=nperseg)


def mark_modes(ax, modes, label) -> None:
    """A dashed vertical line at each of ``modes``' frequency, in its colour, labelled
    ``label(mode)``."""
    for m in modes:
        ax.axvline(m.frequency_hz, color=mode_colour(m.mode), ls='--', lw=1.0, label=label(m))


def plot_spectrum(ax, t: np.ndarray, y: np.ndarray, modes, unit: str = UNKNOWN_UNIT) -> None:
    """The Welch PSD of the signal on ``ax`` (log scale), each of ``modes``
    (:class:`.summary.ModeSummary`) marked at its median frequency, labelled "f = ... Hz"."""
    if len(y) < 2:
        ax.text(0.5, 0.5, 'too few samples for a spectrum', transform=ax.transAxes, ha='center')
        return
    f, psd = welch_psd(t, y, min((m.frequency_hz for m in modes), default=math.nan))
    ax.semilogy(f[1:], psd[1:], lw=0.8, color='0.3', label='Welch PSD')
    mark_modes(
        ax,
        modes,
        lambda m: f'f = {m.frequency_hz:.5g} Hz' + (f' (mode {m.mode})' if m.mode else ''),
    )
    if modes:
        ax.set_xlim(0, min(f[-1], PSD_SPAN * max(m.frequency_hz for m in modes)))
    ax.set_xlabel('frequency (Hz)')
    ax.set_ylabel(f'PSD (({unit})²/Hz)')
    ax.set_title('spectrum, estimated modes marked (median of the estimates)', fontsize=9)
    ax.legend(loc='upper right', fontsize=8)
