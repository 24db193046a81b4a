# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``analyze --report DIR [--geometry FILE]``: one self-contained HTML page an engineer can hand
on (docs/report.md).

``DIR/index.html`` and its images beside it (PNG, and an animated GIF per mode shape drawn on a
geometry); no network, no JavaScript. The page holds: the record and the exact command line; the
modes (frequency and damping with their robust stds, the recommended input shaper and its
``shaper_node`` command: :mod:`.summary`); the spectrum -- one channel: its Welch PSD; several:
the singular values of the cross-spectral matrix -- with each mode marked; for ``excitation
ambient`` a stabilisation diagram (the SSI-cov poles of the record's last window over the model
orders, those of the estimator's stable clusters coloured: :mod:`..core.ambient`,
:mod:`..core.ssi`); frequency and damping over time with their stds; each mode's shape,
on the geometry (deformed over undeformed, animated) or as a bar plot of the channels' signed
amplitudes and phases; the MAC matrix between the modes; the counters and, when nothing was
estimated, why. Everything shown comes from the run's estimates: nothing is estimated again.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional, Sequence

import numpy as np

from ..core.config import EstimatorConfig
from ..core.estimator import EstimateArrays
from ..core.shapes import mac, phases_deg, signed_amplitudes
from ..io.fields import UNKNOWN_UNIT
from .plotting import PSD_RESOLUTION, mark_modes, mode_colour, pyplot, save_figure, welch_psd
from .summary import ModeSummary, renumber, summarise_modes, summary_lines

#: frames of a mode shape's animation (one period) and their rate, frames/s
GIF_FRAMES = 12
GIF_FPS = 8
GIF_DPI = 80
#: the largest displacement of an animated shape, as a fraction of the structure's extent
SHAPE_SCALE = 0.12
#: the spectrum's axis spans 0 .. this x the highest mode's frequency (Nyquist at most)
SPAN = 1.5
#: the most error bars drawn per mode in the estimates over time
MAX_BARS = 60
#: the spectrum's frequency bins between the two closest modes
RESOLVE = 4.0


@dataclass
class Record:
    """What a run of ``analyze`` gives the report: the input ``name``, the ``command`` line, the
    ``channels`` and the samples ``t``, ``y`` (samples x channels), the ``estimates``, with
    several channels each estimate's complex ``shapes`` (estimates x channels), the ``config``,
    the estimator's ``counters``, the signal ``unit`` and, with no estimate, ``why``."""

    name: str
    command: str
    channels: tuple[str, ...]
    t: np.ndarray
    y: np.ndarray
    estimates: EstimateArrays
    config: EstimatorConfig
    counters: dict
    shapes: Optional[np.ndarray] = None
    unit: str = UNKNOWN_UNIT
    why: str = ''
    modes: list = field(default_factory=list)
    #: per mode, per stretch of its estimates when its frequency moved (:mod:`.summary`)
    stretches: list = field(default_factory=list)

    def __post_init__(self):
        self.y = np.asarray(self.y, dtype=float).reshape(len(self.t), -1)
        e = self.estimates
        #: each estimate's mode by identity, as the summary numbers them (.summary.renumber)
        self.mode = renumber(e.frequency_hz, e.mode, e.t)
        self.modes = summarise_modes(e.frequency_hz, e.damping, self.mode)
        self.stretches = summarise_modes(e.frequency_hz, e.damping, self.mode, e.t)


def command_line(args) -> str:
    """The command line of ``args`` (as :func:`..cli.main` keeps it), quoted for a shell."""
    import shlex
    import sys

    return shlex.join(getattr(args, 'argv', None) or ['vib-estimator', *sys.argv[1:]])


# ---- per-mode numbers ---------------------------------------------------------------------------
def mode_shape(record: Record, mode: ModeSummary) -> np.ndarray:
    """The mode's complex shape: the median of its estimates' real and imaginary parts
    (normalised shapes); one channel: ``[1]``."""
    if record.shapes is None or len(record.channels) < 2:
        return np.ones(len(record.channels), dtype=complex)
    s = record.shapes[record.mode == mode.mode]
    return np.median(s.real, axis=0) + 1j * np.median(s.imag, axis=0)


def damping_std(record: Record, mode: ModeSummary) -> float:
    """The median of the mode's estimates' damping std (NaN if none)."""
    e = record.estimates
    z = e.damping_std[(record.mode == mode.mode) & np.isfinite(e.damping_std)]
    return float(np.median(z)) if len(z) else math.nan


def mac_matrix(shapes: Sequence[np.ndarray]) -> np.ndarray:
    """The MAC (:func:`..core.shapes.mac`) of every pair of ``shapes``."""
    return np.array([[mac(a, b) for b in shapes] for a in shapes]).reshape(len(shapes), -1)


def mode_name(m: ModeSummary) -> str:
    return f'mode {m.mode}' if m.mode else 'mode'


# ---- figures ------------------------------------------------------------------------------------
def _mark_band(ax, config: EstimatorConfig, hi: float) -> None:
    """Shade what lies outside ``band_hz`` (the estimator does not look there)."""
    if config.band_hz is None:
        return
    lo, top = config.band_hz
    ax.axvspan(0, lo, color='0.9', zorder=0, label='outside --band-hz')
    if top < hi:
        ax.axvspan(top, hi, color='0.9', zorder=0)


def _mark_modes(ax, modes) -> None:
    mark_modes(
        ax,
        modes,
        lambda m: (
            f'{mode_name(m)}: {m.frequency_hz:.4g} Hz'
            + (f' (t {m.t_first:.3g}–{m.t_last:.3g} s)' if m.stretches > 1 else '')
        ),
    )


def resolution_hz(modes) -> float:
    """What :func:`.plotting.welch_psd` takes as the lowest mode so that its segments resolve
    the lowest mode and the closest pair of modes (:data:`RESOLVE` bins between them)."""
    f = sorted(m.frequency_hz for m in modes)
    if not f:
        return math.nan
    gap = min(np.diff(f), default=f[0])
    return min(f[0], PSD_RESOLUTION * gap / RESOLVE)


def _visible_ylim(ax, f, curves, hi_hz: float) -> None:
    """A log axis spanning the plotted curves over 0 .. ``hi_hz`` only."""
    sel = (f > 0) & (f <= hi_hz)
    values = np.concatenate([c[sel] for c in curves]) if np.any(sel) else np.empty(0)
    values = values[np.isfinite(values) & (values > 0)]
    if len(values):
        ax.set_ylim(values.min() / 2, values.max() * 2)


def spectral_singular_values(t, y, lowest_hz: float):
    """(frequencies Hz, singular values of the cross-spectral matrix, descending, one column
    each): Welch estimates of every channel pair with :func:`.plotting.welch_psd`'s segments."""
    from scipy.signal import csd

    f, _ = welch_psd(t, y[:, 0], lowest_hz)
    nperseg = 2 * (len(f) - 1)
    fs = 1.0 / float(np.median(np.diff(t)))
    y = y - y.mean(axis=0)
    m = y.shape[1]
    g = np.empty((len(f), m, m), dtype=complex)
    for i in range(m):
        for j in range(i, m):
            _, g[:, i, j] = csd(y[:, i], y[:, j], fs=fs, nperseg=nperseg)
            g[:, j, i] = np.conj(g[:, i, j])
    return f, np.linalg.svd(g, compute_uv=False)


def spectrum_figure(path: Path, record: Record) -> None:
    """The PSD (one channel) or the singular values of the spectral matrix, modes marked."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(9, 4.2))
    lowest = resolution_hz(record.stretches)
    t, y, unit = record.t, record.y, record.unit
    if len(t) < 4 or not np.any(np.ptp(y, axis=0) > 0):
        text = 'too few samples for a spectrum' if len(t) < 4 else 'constant signal: no spectrum'
        ax.text(0.5, 0.5, text, transform=ax.transAxes, ha='center')
    elif y.shape[1] == 1:
        f, psd = welch_psd(t, y[:, 0], lowest)
        curves = [psd]
        ax.semilogy(
            f[1:], psd[1:], color='0.3', lw=0.8, label=f'Welch PSD of {record.channels[0]}'
        )
        ax.set_title('spectrum of the signal, the estimated modes marked')
    else:
        f, sv = spectral_singular_values(t, y, lowest)
        curves = [sv[:, k] for k in range(min(3, sv.shape[1]))]
        for k in range(min(3, sv.shape[1])):
            ax.semilogy(
                f[1:], sv[1:, k], lw=0.9 if k == 0 else 0.6, label=f'singular value {k + 1}'
            )
        ax.set_title(
            f'singular values of the spectral matrix ({y.shape[1]} channels), modes marked'
        )
    if ax.lines:
        _mark_modes(ax, record.stretches)
        top = max((m.frequency_hz for m in record.modes), default=0.0)
        hi = min(f[-1], SPAN * top) if top > 0 else f[-1]
        _mark_band(ax, record.config, hi)
        ax.set_xlim(0, hi)
        _visible_ylim(ax, f, curves, hi)
        ax.legend(fontsize='small', loc='upper left', bbox_to_anchor=(1.0, 1.0))
    ax.set_xlabel('frequency (Hz)')
    ax.set_ylabel(f'PSD (({unit})²/Hz)')
    save_figure(fig, [ax], str(path))


def stabilisation_poles(record: Record):
    """(model orders, the SSI-cov poles of the record's last window at each order, the stable
    clusters' rows, the rate they are at), computed as the ambient estimators do
    (:func:`..core.ssi.ssi_poles` of the window's correlations at the rate
    :func:`..core.ssi.decimation_level` picks for the highest mode)."""
    from ..core import ssi
    from ..core.ambient import COUNTER_NAMES
    from ..core.correlations import CorrelationCascade

    fs = 1.0 / float(np.median(np.diff(record.t)))
    n = min(len(record.t), round(record.config.ambient_window_s * fs))
    y = record.y[-n:]
    cascade = CorrelationCascade.of(y, 2 * ssi.block_rows(y.shape[1]))
    top = max((md.frequency_hz for md in record.modes), default=0.0)
    level = ssi.decimation_level(cascade, fs, top) if top > 0 else 0
    rate = fs / 2**level
    poles = ssi.ssi_poles(cascade.correlations(level), rate)
    band = record.config.band_hz or (0.0, math.inf)
    counts = dict.fromkeys(COUNTER_NAMES, 0)
    stable = ssi.stable_clusters(poles, rate, record.config.max_damping, band, counts)
    return ssi.ORDERS, poles, stable, rate


def stabilisation_figure(path: Path, record: Record) -> None:
    """Frequency against model order: every pole (grey), those of stable clusters (coloured by
    the nearest mode), the modes marked."""
    orders, poles, stable, rate = stabilisation_poles(record)
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(9, 4.2))
    for order, p in zip(orders, poles):
        ax.plot(p[:, 0], np.full(len(p), order), '.', color='0.75', ms=3)
    ax.plot([], [], '.', color='0.75', label='pole (any)')
    for group in stable:
        f = float(np.median(group[:, 0]))
        near = min(record.modes, key=lambda m: abs(m.frequency_hz - f), default=None)
        colour = mode_colour(near.mode) if near and abs(near.frequency_hz / f - 1) < 0.03 else 'k'
        ax.plot(
            group[:, 0],
            np.asarray(orders)[group[:, -2].astype(int)],
            'o',
            mfc='none',
            color=colour,
            ms=5,
        )
    ax.plot([], [], 'o', mfc='none', color='k', label='stable pole (a cluster over the orders)')
    _mark_modes(ax, record.stretches)
    top = max((m.frequency_hz for m in record.modes), default=0.45 * rate)
    hi = min(0.5 * rate, SPAN * top)
    _mark_band(ax, record.config, hi)
    ax.set_xlim(0, hi)
    ax.set_xlabel('frequency (Hz)')
    ax.set_ylabel('model order')
    ax.set_title(
        f'stabilisation diagram: SSI-cov of the last {record.config.ambient_window_s:g} s '
        f'(at {rate:g} Hz)'
    )
    ax.legend(fontsize='small', loc='upper left', bbox_to_anchor=(1.0, 1.0))
    save_figure(fig, [ax], str(path))


def tracks_figure(path: Path, record: Record) -> None:
    """Frequency (one mode: Hz; several: relative to each mode's median, %) and, when the model
    estimates it, damping ratio over time by mode, error bars 1 std (at most :data:`MAX_BARS` a
    mode)."""
    plt = pyplot()
    e = record.estimates
    damped = bool(np.any(np.isfinite(e.damping)))
    fig, axes = plt.subplots(2 if damped else 1, 1, figsize=(9, 5.6 if damped else 3.4),
                             sharex=True, squeeze=False)  # fmt: skip
    axes = axes[:, 0]
    several = len(record.modes) > 1
    for m in record.modes:
        sel = record.mode == m.mode
        f = 100 * (e.frequency_hz[sel] / m.frequency_hz - 1) if several else e.frequency_hz[sel]
        fstd = (
            100 * e.frequency_std_hz[sel] / m.frequency_hz if several else e.frequency_std_hz[sel]
        )
        series = ((f, fstd), (e.damping[sel], e.damping_std[sel]))
        for ax, (value, std) in zip(axes, series):
            ax.errorbar(
                e.t[sel],
                value,
                yerr=np.where(np.isfinite(std), std, 0.0),
                errorevery=max(1, int(np.count_nonzero(sel)) // MAX_BARS),
                fmt='.',
                ms=3,
                lw=0.6,
                color=mode_colour(m.mode),
                label=f'{mode_name(m)}: {m.frequency_hz:.4g} Hz',
            )
    axes[0].set_ylabel('frequency - median (%)' if several else 'frequency (Hz)')
    axes[-1].set_xlabel('time (s)')
    axes[0].set_title(
        'estimates over time (error bars: 1 std)'
        + ('' if damped else '; damping not estimated by this model (--model damped-sinusoid)'),
        fontsize=None if damped else 10,
    )
    if damped:
        axes[1].set_ylabel('damping ratio ζ')
    if record.modes:
        axes[0].legend(fontsize='small', loc='upper left', bbox_to_anchor=(1.0, 1.0))
    save_figure(fig, axes, str(path))


def bars_figure(path: Path, record: Record, mode: ModeSummary, shape: np.ndarray) -> None:
    """A mode's shape without geometry: each channel's signed amplitude (bars, error bars the
    median ``shape_std`` is not kept here) and phase (degrees)."""
    plt = pyplot()
    fig, (ax, ph) = plt.subplots(
        2, 1, figsize=(max(4.0, 0.6 * len(shape) + 2), 4.6), height_ratios=(2, 1), sharex=True
    )
    x = np.arange(len(shape))
    ax.bar(x, signed_amplitudes(shape), color=mode_colour(mode.mode))
    ax.axhline(0.0, color='k', lw=0.5)
    ax.set_ylim(-1.05, 1.05)
    ax.set_ylabel('signed amplitude\n(unit-length shape)')
    ax.set_title(f'{mode_name(mode)}: {mode.frequency_hz:.4g} Hz, shape by channel')
    ph.plot(x, phases_deg(shape), 'o', color=mode_colour(mode.mode))
    ph.set_ylim(-190, 190)
    ph.set_yticks([-180, -90, 0, 90, 180])
    ph.set_ylabel('phase (°)')
    ph.set_xticks(x, record.channels, rotation=60 if len(x) > 6 else 0, fontsize='small')
    ph.set_xlabel('channel')
    save_figure(fig, [ax, ph], str(path))


def _equal_box(ax, points: np.ndarray) -> None:
    """Equal scales on a 3-D axis around ``points`` (a flat axis gets a quarter of the rest)."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, half = (lo + hi) / 2, max(float(np.max(hi - lo)) / 2, 1e-9) * 1.15
    span = np.maximum((hi - lo) / 2 * 1.15, 0.25 * half)
    for setter, c, s in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, span):
        setter(c - s, c + s)
    ax.set_box_aspect(tuple(span))


def view_axes(points: np.ndarray, disp: np.ndarray) -> tuple[int, int]:
    """The two axes of the flat view: the axis along which the shape moves least is dropped
    (ties: the one along which the structure is thinnest)."""
    moves = np.max(np.abs(disp), axis=0)
    extent = np.ptp(points, axis=0)
    drop = min(
        range(3), key=lambda k: (round(float(moves[k] / (moves.max() or 1.0)), 6), extent[k])
    )
    return tuple(k for k in range(3) if k != drop)


def _shape_axes(fig, geometry, frames, colour, view):
    """The 3-D and the flat axes, the undeformed wireframe drawn on both; the moving lines and
    sensor dots of each."""
    base = geometry.points
    ax3 = fig.add_subplot(1, 2, 1, projection='3d')
    ax2 = fig.add_subplot(1, 2, 2)
    _equal_box(ax3, np.concatenate([base, *frames]))
    everything = np.concatenate([base, *frames])[:, view]
    pad = 0.08 * max(float(np.max(np.ptp(everything, axis=0))), 1e-9)
    ax2.set_xlim(everything[:, 0].min() - pad, everything[:, 0].max() + pad)
    ax2.set_ylim(everything[:, 1].min() - pad, everything[:, 1].max() + pad)
    ax2.set_aspect('equal')
    names = 'xyz'
    ax2.set_xlabel(f'{names[view[0]]} (m)')
    ax2.set_ylabel(f'{names[view[1]]} (m)')
    for label, ax in zip('xyz', (ax3.set_xlabel, ax3.set_ylabel, ax3.set_zlabel)):
        ax(f'{label} (m)')
    for a, b in geometry.lines:
        ax3.plot(*base[[a, b]].T, color='0.6', lw=1.0, ls='--')
        ax2.plot(*base[[a, b]][:, view].T, color='0.6', lw=1.0, ls='--')
    if geometry.fixed:
        ax3.plot(*base[list(geometry.fixed)].T, 'k^', ms=6)
        ax2.plot(*base[list(geometry.fixed)][:, view].T, 'k^', ms=6)
    lines3 = [ax3.plot([], [], [], color=colour, lw=2.0)[0] for _ in geometry.lines]
    lines2 = [ax2.plot([], [], color=colour, lw=2.0)[0] for _ in geometry.lines]
    dots3 = ax3.plot([], [], [], 'o', color=colour, ms=4)[0]
    dots2 = ax2.plot([], [], 'o', color=colour, ms=4)[0]
    ax2.grid(alpha=0.3)
    flat = np.ptp(base, axis=0) == 0
    for setter, value, is_flat in zip(
        (ax3.set_xticks, ax3.set_yticks, ax3.set_zticks), base[0], flat
    ):
        if is_flat:  # a planar structure: one tick on the axis it does not extend along
            setter([value])
    fig.subplots_adjust(left=0.02, right=0.97, bottom=0.15, top=0.86, wspace=0.35)
    return (lines3, dots3), (lines2, dots2)


def shape_animation(path: Path, geometry, record, mode: ModeSummary, shape: np.ndarray) -> None:
    """A mode's shape on the geometry, an animated GIF of one period (Pillow; the still parts
    drawn once), in 3-D and in the flat view it moves in (:func:`view_axes`): the undeformed
    wireframe grey and dashed, the deformed one coloured, the sensors' points dotted, the
    supports triangles; the first frame is the largest deflection."""
    plt = pyplot()
    base = geometry.points
    disp = geometry.displacements(shape, record.channels)
    peak = float(np.max(np.abs(disp))) or 1.0
    scale = SHAPE_SCALE * geometry.size / peak
    frames = [
        base + scale * (disp * np.exp(2j * math.pi * k / GIF_FRAMES)).real
        for k in range(GIF_FRAMES)
    ]
    view = view_axes(base, disp)
    fig = plt.figure(figsize=(6.8, 3.6))
    (lines3, dots3), (lines2, dots2) = _shape_axes(
        fig, geometry, frames, mode_colour(mode.mode), view
    )
    fig.suptitle(
        f'{mode_name(mode)}: {mode.frequency_hz:.4g} Hz, ζ = {_zeta(mode.damping)}; '
        f'{geometry.name}\n(deflection exaggerated)',
        fontsize=7,
    )
    sensors = sorted({p for pts in geometry.channel_points for p in pts})
    images = []
    for pts, image in zip(frames, _blitted(fig, [*lines3, *lines2, dots3, dots2])):
        for line3, line2, (a, b) in zip(lines3, lines2, geometry.lines):
            line3.set_data_3d(*pts[[a, b]].T)
            line2.set_data(*pts[[a, b]][:, view].T)
        dots3.set_data_3d(*pts[sensors].T)
        dots2.set_data(*pts[sensors][:, view].T)
        images.append(image())
    plt.close(fig)
    images[0].save(
        path, save_all=True, append_images=images[1:], duration=round(1000 / GIF_FPS), loop=0
    )


def _blitted(fig, moving):
    """Per frame, after the caller moved the ``moving`` artists: a callable giving the frame as
    a palette image (the still parts drawn once, at :data:`GIF_DPI`, the moving ones blitted over
    them)."""
    from PIL import Image

    fig.set_dpi(GIF_DPI)
    for artist in moving:
        artist.set_animated(True)
    canvas = fig.canvas
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)

    def image():
        canvas.restore_region(background)
        for artist in moving:
            artist.axes.draw_artist(artist)
        rgba = Image.frombuffer('RGBA', canvas.get_width_height(), bytes(canvas.buffer_rgba()))
        return rgba.convert('RGB').convert('P', palette=Image.Palette.ADAPTIVE)

    while True:
        yield image


def mac_figure(path: Path, modes, shapes) -> None:
    """The MAC matrix between the modes' shapes, values written in the cells."""
    plt = pyplot()
    matrix = mac_matrix(shapes)
    n = len(modes)
    fig, ax = plt.subplots(figsize=(1.0 + 0.7 * n, 0.6 + 0.7 * n))
    im = ax.imshow(matrix, vmin=0, vmax=1, cmap='Blues')
    labels = [f'{m.mode}: {m.frequency_hz:.3g} Hz' for m in modes]
    ax.set_xticks(range(n), labels, rotation=45, ha='right', fontsize='small')
    ax.set_yticks(range(n), labels, fontsize='small')
    for i in range(n):
        for j in range(n):
            ax.text(
                j,
                i,
                f'{matrix[i, j]:.2f}',
                ha='center',
                va='center',
                color='w' if matrix[i, j] > 0.6 else 'k',
                fontsize='small',
            )
    ax.set_title('MAC between the modes (1: same shape)', fontsize=9)
    fig.colorbar(im, ax=ax, fraction=0.046)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ---- the page -----------------------------------------------------------------------------------
def _zeta(value: float) -> str:
    return f'{value:.4f}' if math.isfinite(value) else 'not estimated'


def _std(value: float, digits: str = '.2g') -> str:
    return f'± {value:{digits}}' if math.isfinite(value) else ''


def _figure(src: str, caption: str, alt: str) -> str:
    return (
        f'<figure><img src="{html.escape(src)}" alt="{html.escape(alt)}">'
        f'<figcaption>{caption}</figcaption></figure>'
    )


def modes_table(record: Record, shapes) -> str:
    """The modes' table: frequency and damping with their stds, estimates, shape."""
    head = (
        '<tr><th>mode</th><th>frequency (Hz)</th><th>damping ratio ζ</th>'
        '<th>estimates</th>'
        + ('<th>shape (signed amplitude per channel)</th>' if shapes else '')
        + '</tr>'
    )
    rows = []
    shape_of = dict(zip((m.mode for m in record.modes), shapes or [None] * len(record.modes)))
    for m in record.stretches:
        shape = shape_of.get(m.mode)
        when = f' (t {m.t_first:.4g}–{m.t_last:.4g} s)' if m.stretches > 1 else ''
        cells = [
            f'<td class="mode" data-mode="{m.mode}">{m.mode or "-"}{when}</td>',
            f'<td>{m.frequency_hz:.4f} {_std(m.frequency_std_hz)}</td>',
            f'<td>{_zeta(m.damping)} {_std(damping_std(record, m))}</td>',
            f'<td>{m.count}'
            + (f' ({m.outliers} outliers)' if m.outliers else '')
            + (' (tentative: too few to shape for)' if m.tentative else '')
            + '</td>',
        ]
        if shape is not None:
            amp = signed_amplitudes(shape)
            cells.append(
                '<td>'
                + ', '.join(f'{html.escape(c)} {a:+.2f}' for c, a in zip(record.channels, amp))
                + '</td>'
            )
        rows.append('<tr>' + ''.join(cells) + '</tr>')
    return f'<table>{head}{"".join(rows)}</table>'


STYLE = (
    'body{font-family:sans-serif;max-width:1100px;margin:1em auto;padding:0 1em;color:#222}'
    'table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #ccc;padding:3px 8px;'
    'text-align:left;font-size:0.92em}th{background:#f0f0f0}pre{background:#f6f6f6;padding:0.6em;'
    'white-space:pre-wrap;word-break:break-all}figure{margin:0.8em 0;display:inline-block;'
    'vertical-align:top}img{max-width:100%}figcaption{font-size:0.85em;color:#555;max-width:540px}'
    '.note{font-size:0.85em;color:#555}'
    '.why{background:#fff4e0;border-left:4px solid #e90;padding:0.5em 1em}'
)


def record_html(record: Record, geometry) -> str:
    """The record, the command line and the configuration."""
    t = record.t
    fs = 1.0 / float(np.median(np.diff(t))) if len(t) > 1 else math.nan
    span = float(t[-1] - t[0]) if len(t) else 0.0
    items = [
        ('record', record.name),
        ('channels', ', '.join(record.channels)),
        ('samples', f'{len(t)} over {span:.4g} s (sampled at {fs:.4g} Hz)'),
        ('excitation, model', f'{record.config.excitation}, {record.config.model}'),
        (
            'geometry',
            f'{geometry.name} ({geometry.path})' if geometry else 'none (--geometry FILE)',
        ),
    ]
    rows = ''.join(f'<tr><th>{k}</th><td>{html.escape(v)}</td></tr>' for k, v in items)
    return (
        f'<table>{rows}</table><p>Command line (re-run it to reproduce this page):</p>'
        f'<pre>{html.escape(record.command)}</pre>'
    )


def shaper_html(record: Record) -> str:
    """The recommended input shaper as ``analyze`` gives it (:func:`.summary.summary_lines` of
    the estimates by mode and stretch): why, and the ``shaper_node`` command -- or why none."""
    e = record.estimates
    lines = summary_lines(summarise_modes(e.frequency_hz, e.damping, e.mode, e.t))
    start = next(
        (i for i, line in enumerate(lines) if line.startswith(('recommended', 'no input shaper'))),
        len(lines),
    )
    text, command = lines[start : start + 1], lines[start + 1 : start + 2]
    return (
        '<h3>Recommended input shaper</h3>'
        + ''.join(f'<p>{html.escape(t.rstrip(":"))}{":" if command else ""}</p>' for t in text)
        + ''.join(f'<pre>{html.escape(c.strip())}</pre>' for c in command)
    )


def counters_html(record: Record) -> str:
    cells = ''.join(
        f'<tr><td>{html.escape(str(k))}</td><td>{v}</td></tr>' for k, v in record.counters.items()
    )
    return (
        "<h2>Counters</h2><details><summary>the estimator's counters (samples used and skipped, "
        f'analyses, candidates rejected and why)</summary><table>{cells}</table></details>'
    )


def shapes_html(directory: Path, record: Record, geometry, shapes) -> str:
    """Each mode's shape: on the geometry (animated GIF) or as bars; the MAC matrix."""
    if len(record.channels) < 2 and geometry is None:
        return (
            '<p>One channel: a mode shape needs several channels (or --geometry to draw it).</p>'
        )
    parts = []
    for m, shape in zip(record.modes, shapes):
        if geometry is not None:
            name = f'shape_mode{m.mode}.gif'
            shape_animation(directory / name, geometry, record, m, shape)
            caption = (
                f'{mode_name(m)}, {m.frequency_hz:.4f} Hz, ζ = {_zeta(m.damping)}: '
                'deformed (coloured, one period) over undeformed (grey, dashed)'
            )
        else:
            name = f'shape_mode{m.mode}.png'
            bars_figure(directory / name, record, m, shape)
            caption = (
                f'{mode_name(m)}, {m.frequency_hz:.4f} Hz, ζ = {_zeta(m.damping)}: '
                'signed amplitude and phase per channel (--geometry draws it on the '
                'structure)'
            )
        parts.append(_figure(name, caption, f'shape of {mode_name(m)}'))
    if len(record.modes) > 1 and len(record.channels) > 1:
        mac_figure(directory / 'mac.png', record.modes, shapes)
        parts.append(
            _figure(
                'mac.png',
                "MAC between the modes' shapes: 1 on the diagonal; distinct modes near 0 (with "
                'few channels two modes may look alike: their frequencies tell them apart)',
                'MAC matrix',
            )
        )
    return ''.join(parts)


def figures_html(directory: Path, record: Record) -> str:
    """The spectrum, the stabilisation diagram (ambient) and the estimates over time."""
    spectrum_figure(directory / 'spectrum.png', record)
    several = len(record.channels) > 1
    parts = [
        _figure(
            'spectrum.png',
            (
                'Singular values of the cross-spectral matrix (Welch): a mode is a peak of the '
                'first'
                if several
                else 'Welch power spectral density of the signal'
            )
            + '; dashed lines: the modes estimated (median of their estimates).',
            'spectrum',
        )
    ]
    if record.config.excitation == 'ambient' and len(record.t) > 1 and record.modes:
        stabilisation_figure(directory / 'stabilisation.png', record)
        parts.append(
            _figure(
                'stabilisation.png',
                (
                    'Stabilisation diagram of the last window: a physical mode gives a pole at '
                    'the same frequency at most model orders (circles); dashed lines: the modes '
                    'published over the record.'
                ),
                'stabilisation diagram',
            )
        )
    if len(record.estimates):
        tracks_figure(directory / 'tracks.png', record)
        parts.append(
            _figure(
                'tracks.png',
                'Frequency and damping ratio of each estimate, with their standard deviations.',
                'estimates over time',
            )
        )
    return ''.join(parts)


def write_report(directory, record: Record, geometry=None) -> Path:
    """Write ``directory/index.html`` and its images (the directory is created); return the
    page's path."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    shapes = [mode_shape(record, m) for m in record.modes]
    title = f'vib_estimator report: {Path(record.name).name}'
    body = [f'<h1>{html.escape(title)}</h1>', record_html(record, geometry), '<h2>Modes</h2>']
    if record.modes:
        body.append(modes_table(record, shapes if len(record.channels) > 1 else None))
        body.append(
            '<p class="note">Frequency: the median of the mode\'s estimates ± their robust '
            "standard deviation; damping ratio: the median ± the median of its estimates' "
            'stds. A mode whose frequency moved during the record (a changed load) is listed per '
            'stretch, with its times.</p>'
        )
        body.append(shaper_html(record))
    else:
        body.append(f'<p class="why"><b>No estimate.</b> Why: {html.escape(record.why)}</p>')
    body.append('<h2>Spectrum and estimates</h2>' + figures_html(directory, record))
    if record.modes:
        body.append('<h2>Mode shapes</h2>' + shapes_html(directory, record, geometry, shapes))
    body.append(counters_html(record))
    return write_page(directory, title, STYLE, body)


def write_page(directory: Path, title: str, style: str, body: Sequence[str]) -> Path:
    """``directory/index.html``: an HTML page of ``title``, inline CSS ``style`` and the
    ``body`` parts; returns its path."""
    page = (
        '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
        f'<title>{html.escape(title)}</title><style>{style}</style></head><body>'
        + '\n'.join(body)
        + '</body></html>\n'
    )
    path = directory / 'index.html'
    path.write_text(page, encoding='utf-8')
    return path


# ---- survey --report ----------------------------------------------------------------------------
#: the survey rows' columns the page shows: (heading, row key, format)
SURVEY_COLUMNS = (
    ('recording', 'recording', '{}'),
    ('start (UTC)', 'start_utc', '{}'),
    ('topic', 'topic', '{}'),
    ('component', 'component', '{}'),
    ('mode', 'mode', '{}'),
    ('frequency (Hz)', 'frequency_hz', '{:.5f}'),
    ('95 % interval (Hz)', ('frequency_lo_hz', 'frequency_hi_hz'), '{:.5f} – {:.5f}'),
    ('damping ratio', 'damping', '{:.4f}'),
    ('estimates', 'estimates', '{}'),
    ('change vs baseline', 'change_rel', '{:+.3%}'),
    ('alarm', 'alarm', '{}'),
    ('error', 'error', '{}'),
)


def _cell(row: dict, key, fmt: str) -> str:
    keys = key if isinstance(key, tuple) else (key,)
    values = [row.get(k) for k in keys]
    if any(v is None or (isinstance(v, float) and not math.isfinite(v)) for v in values):
        return ''
    if key == 'alarm':
        return 'ALARM' if values[0] else ''
    return fmt.format(*values)


def write_survey_report(directory, rows, command: str, baseline, trend: bool) -> Path:
    """``survey --report DIR``: ``DIR/index.html`` with the command line, the counts, the trend
    (``trend.png``, drawn by the caller when ``trend``) and one table row per survey row (alarms
    and errors highlighted); returns the page's path."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    recordings = len({r['recording'] for r in rows})
    alarms = sum(bool(r['alarm']) for r in rows)
    errors = sum(bool(r['error']) for r in rows)
    head = ''.join(f'<th>{html.escape(h)}</th>' for h, _, _ in SURVEY_COLUMNS)
    body = []
    for r in rows:
        cls = ' class="alarm"' if r['alarm'] else ' class="error"' if r['error'] else ''
        cells = ''.join(
            f'<td>{html.escape(_cell(r, key, fmt))}</td>' for _, key, fmt in SURVEY_COLUMNS
        )
        body.append(f'<tr{cls}>{cells}</tr>')
    parts = [
        '<h1>vib_estimator survey report</h1>',
        f'<p>Command line:</p><pre>{html.escape(command)}</pre>',
        f'<p>{recordings} recording(s), {len(rows)} row(s): <b>{alarms} alarm(s)</b>, '
        f'{errors} error(s). Baseline: {html.escape(baseline or "none (--baseline)")}.</p>',
    ]
    if trend:
        parts.append(
            _figure(
                'trend.png',
                'Frequency (and damping) of each recording with its 95 % interval; dashed: the '
                'baseline, shaded: the no-alarm band; crosses: alarms.',
                'frequency trend',
            )
        )
    else:
        parts.append('<p class="why">No recording gave a frequency: see the error column.</p>')
    parts.append(f'<h2>Recordings</h2><table><tr>{head}</tr>{"".join(body)}</table>')
    style = (
        STYLE
        + 'tr.alarm td{background:#fde0e0}tr.error td{background:#fff4e0}td{white-space:nowrap}'
    )
    return write_page(directory, 'vib_estimator survey report', style, parts)
