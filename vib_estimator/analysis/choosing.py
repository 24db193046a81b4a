# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""What ``analyze`` and ``survey`` learn from a record before estimating it
(:func:`..core.choice.decide`), and what they say with it.

- The default: with no ``--excitation`` (and no ``--paper``) the excitation and the ambient
  window are the record's (:func:`decided_config`); one line says what was decided, from what,
  and which option overrides it.
- An ``--excitation`` that the record contradicts (free on a record driven throughout, ambient on
  a free decay) costs one ``warning:`` line (:func:`contradiction`).
- No estimate from the identifier: why, with the numbers, and which option helps
  (:func:`window_advice`: the window's correlation times of the record's lowest peak); a
  spectral peak of the record at which the identifier published no mode, while it published
  others: named, with the same numbers (:func:`peaks_without_mode`).

The lines are printed by the command once the record has been read without error (bad input is
one ``error:`` line)."""

from __future__ import annotations

import dataclasses
import itertools
import math
from typing import Iterable, Iterator, Optional, Tuple

import numpy as np

from ..core.ambient import MIN_WINDOW_SAMPLES, beside_analyses
from ..core.choice import (
    DECIDE_S,
    DOMINANT_AGREE,
    DRIVEN_ABOVE,
    FREE_BELOW,
    MODE_GAP,
    RESCUE_BELOW,
    SEGMENT_S,
    TRACKED_MODES,
    Decision,
    decide,
    is_noise,
    peak_window_advice,
)
from ..core.choice import window_advice as choice_window_advice
from ..core.config import EstimatorConfig
from ..core.estimator import EstimateArrays
from ..core.identity import CONFIRM, MATCH_TOL


def decides(args) -> bool:
    """Whether the command line leaves the excitation to the record (no ``--excitation``, no
    ``--paper``)."""
    return getattr(args, 'excitation', None) is None and not getattr(args, 'paper', False)


def window_given(args) -> bool:
    """Whether the command line sets the ambient window (``--ambient-window-s``)."""
    return getattr(args, 'ambient_window_s', None) is not None


def periods_given(args) -> bool:
    """Whether the command line sets the free-decay window (``--min-periods``)."""
    return getattr(args, 'min_periods', None) is not None


def damping_given(args) -> bool:
    """Whether the command line sets ``--max-damping`` (a steady oscillation's is then not
    applied)."""
    return getattr(args, 'max_damping', None) is not None


def model_given(args) -> bool:
    """Whether the command line sets the model or a band (``--model``, ``--band-hz``): the
    decided model and offset are then not applied."""
    return any(getattr(args, name, None) is not None for name in ('model', 'band_hz'))


def decided_config(
    config: EstimatorConfig,
    d: Decision,
    prog: str,
    keep_window: bool = False,
    keep_periods: bool = False,
    keep_damping: bool = False,
) -> Tuple[EstimatorConfig, str]:
    """``config`` with the excitation, (unless ``keep_window``: ``--ambient-window-s`` was
    given) the ambient window, (unless ``config.modes`` is set) the modes to track, (unless
    ``keep_periods``: ``--min-periods`` was given) the free-decay window and model and (unless
    ``keep_damping``: ``--max-damping`` was given) a steady oscillation's ``max_damping`` of the
    decision ``d``, and the line that says so."""
    window = config.ambient_window_s
    if not keep_window and d.excitation != 'free':
        window = d.window_s
    modes = config.modes or d.modes
    periods, early, model = config.min_periods, config.early_std_rel, config.model
    if not keep_periods and math.isfinite(d.min_periods):
        periods, early = d.min_periods, early or d.early_std_rel
        model = d.model or model
    line = (
        f'{prog}: excitation {d.excitation} (the default decides from the record: {d.reason}; '
        '--excitation free, ambient or auto overrides'
        + ('' if d.excitation == 'free' else ', --ambient-window-s the window')
        + (', --min-periods the window' if math.isfinite(d.min_periods) else '')
        + ')'
    )
    changed = config.replace(
        excitation=d.excitation,
        ambient_window_s=window,
        modes=modes,
        min_periods=periods,
        early_std_rel=early,
        model=model,
        lines_hz=config.lines_hz or d.lines_hz or None,
        band_hz=config.band_hz or d.band_hz or None,
        max_damping=(
            d.max_damping
            if math.isfinite(d.max_damping) and not keep_damping
            else config.max_damping
        ),
    )
    return changed, line


#: ... and so is one whose free estimator gives fewer than this share of the estimates its
#: window allows over the periods the decay rings above its noise
#: (:attr:`..core.choice.Decision.ringing_periods`): a lightly damped 5 Hz pluck at 20 samples a
#: period in 20 dB (91 periods ringing: 73 windows of 1.25) gave the damped model 6 estimates,
#: the tracker 50; clean decays give 80-100 % of theirs. ``bench_hard_records.py --silent``
#: (6 Dec): at 20 samples a period in 20 dB 10 -> 22 estimates a record, the least share within
#: 2 % 67 -> 83 %, 60 samples in 30 dB 31 -> 40; 0.25 gave two estimates beyond 5 % at 60
#: samples in 20 dB, 0.1 left the latter at 31
RESCUE_SHARE = 0.15


def rescue(
    config: EstimatorConfig, d: Optional[Decision], decided: bool, estimated: int, prog: str
) -> Optional[Tuple[EstimatorConfig, str]]:
    """For a record decided (``decided``: no option chose the excitation) a free decay of one
    mode whose free estimator gave fewer than :data:`RESCUE_BELOW` estimates (``estimated``), or
    fewer than :data:`RESCUE_SHARE` of those its window allows over the decay's ringing --
    its convergence test (Eqs. 16-17) rarely passing in the record's noise at its samples a
    period, or its fit gate holding back the estimates of a heavily damped decay --: the mode
    tracker's configuration (``modes`` :data:`..core.choice.TRACKED_MODES`, the samples as read)
    and the line that says so (the caller keeps the free estimates where the tracker gives
    fewer); None otherwise (enough estimates, an option, a record with no spectral peak)."""
    if not decided or d is None:
        return None
    window = config.min_periods  # (0: the convergence test's alone, no share asked)
    allowed = RESCUE_SHARE * d.ringing_periods / window if window > 0 else math.nan
    if estimated >= RESCUE_BELOW and not estimated < allowed:
        return None
    if config.excitation != 'free' or config.modes or not d.dominant_hz > 0:
        return None
    gave = (
        f'only {estimated} estimate{"s" if estimated > 1 else ""}' if estimated else 'no estimate'
    )
    if estimated >= RESCUE_BELOW:
        gave += f' (its window allows {allowed / RESCUE_SHARE:.0f} over the decay)'
    line = (
        f'{prog}: the free estimator gave {gave} of this free decay at {d.dominant_hz:.4g} '
        f'Hz: the mode tracker (modes {TRACKED_MODES}) estimated it; --excitation free keeps the '
        'free estimator'
    )
    return config.replace(modes=TRACKED_MODES), line


def dominant_reading(
    config: EstimatorConfig, d: Optional[Decision], allowed: bool
) -> Optional[Tuple[EstimatorConfig, float]]:
    """For a free decay of several modes decided from the record (``allowed``: no option chose
    the excitation, the modes, the model or the window) whose strongest mode the free estimator
    reads (:attr:`..core.choice.Decision.dominant_window`): the free estimator's configuration
    for that mode and the offset to remove from the samples first (0: none); None otherwise.
    The mode tracker reads the others (:func:`with_dominant`)."""
    if not allowed or d is None or not d.dominant_window or config.excitation != 'free':
        return None
    periods, early, model, offset = d.dominant_window
    free = config.replace(
        modes=0, min_periods=periods, early_std_rel=early, model=model or config.model
    )
    return free, (offset if math.isfinite(offset) else 0.0)


def with_dominant(tracked: EstimateArrays, free: EstimateArrays) -> Tuple[EstimateArrays, str]:
    """The mode tracker's estimates ``tracked`` with those of the mode the free estimator read
    (``free``: its estimates within :data:`..core.choice.MODE_GAP` of their median; separate
    modes lie farther apart) in place of the tracker's mode nearest it within that gap (its
    number; else a new one) from the free estimator's first estimate on (the tracker's before
    it: after rest, the tracker's first can come earlier), and the words that say so ('' when
    the free estimator gave none: the tracker's, as they were). Where the tracker's windows of
    that mode are no longer than the free estimator's (median: its fast scale engaged), or the
    free estimates stray from the tracker's median of that mode by more than
    :data:`..core.choice.DOMINANT_AGREE` (median relative deviation: the other modes bias its
    one-mode window), the tracker's, as they were, and the words that say why."""
    if not len(free):
        return tracked, ''
    f = float(np.median(free.frequency_hz))
    free = free.where(np.abs(free.frequency_hz / f - 1) < MODE_GAP)
    f = float(np.median(free.frequency_hz))
    medians = {
        int(m): float(np.median(tracked.frequency_hz[tracked.mode == m]))
        for m in np.unique(tracked.mode)
    }
    near = [m for m, g in medians.items() if abs(g / f - 1) < MODE_GAP]
    number = (
        min(near, key=lambda m: abs(medians[m] / f - 1)) if near else max(medians, default=0) + 1
    )
    kept = tracker_kept(tracked.where(tracked.mode == number), free) if near else ''
    if kept:
        return tracked, (
            f'mode {number} ({medians[number]:.4g} Hz), the strongest and lowest: the mode '
            f"tracker's estimates ({kept})"
        )
    mine = (tracked.mode == number) & (tracked.t >= free.t[0])
    free.mode[:] = number
    words = (
        f'mode {number} ({f:.4g} Hz), the strongest and lowest, the others weak: from t = '
        f"{free.t[0]:.4g} s the free estimator's {len(free)} estimates (a pure peak: its short "
        f"window) in place of the mode tracker's {int(np.sum(mine))} (the counters: the "
        "tracker's; --modes keeps the tracker's)"
    )
    return EstimateArrays.concatenate([tracked.where(~mine), free]), words


def tracker_kept(mode: EstimateArrays, free: EstimateArrays) -> str:
    """Why the tracker's estimates of a ``mode`` stay in place of the free estimator's of it
    (``free``), in words: its windows no longer (median), or the free estimates straying from
    its median by more than :data:`..core.choice.DOMINANT_AGREE`; '' when the free estimates
    replace them (:func:`with_dominant`)."""
    g = float(np.median(mode.frequency_hz))
    window = float(np.median(mode.convergence_time))
    if window <= float(np.median(free.convergence_time)):
        return f"its windows no longer than the free estimator's: {window * g:.2f} periods"
    stray = float(np.median(np.abs(free.frequency_hz / g - 1)))
    if stray > DOMINANT_AGREE:
        return (
            f"the free estimator's short window strays {100 * stray:.2g} % from them, the "
            'other modes in it'
        )
    return ''


def contradiction(config: EstimatorConfig, d: Decision, prog: str) -> str:
    """One ``warning:`` line when the chosen excitation contradicts the record (free decays'
    estimates of a driven record scatter -- not of a train of plucks,
    ``Decision.plucks_in_a_row`` --; the identifier needs a stationary response), else ''."""
    share = f'{100 * d.driven_share:.0f} % of its energy read driven'
    driven = d.driven_share > DRIVEN_ABOVE and not d.plucks_in_a_row
    if config.excitation == 'free' and driven:
        return (
            f'{prog}: warning: the record looks driven throughout ({share}): free-decay estimates '
            'of a driven structure scatter; without --excitation the default would use ambient'
        )
    if config.excitation == 'ambient' and (d.driven_share < FREE_BELOW or d.plucks_in_a_row):
        if d.plucks_in_a_row:
            share = f'{100 * d.train:.0f} % of its stretches clean free decays, plucks in a row'
        return (
            f'{prog}: warning: the record looks like free decays ({share}): the identifier '
            'needs a stationary response; without --excitation the default would use free'
        )
    return ''


def window_advice(config: EstimatorConfig, d: Optional[Decision]) -> str:
    """Why a window gave no mode, from the record's lowest spectral peak
    (:func:`..core.choice.window_advice`, the option ``analyze`` takes); '' without one."""
    return choice_window_advice(config.ambient_window_s, d, '--ambient-window-s ')


def peaks_without_mode(config: EstimatorConfig, d: Optional[Decision], found_hz) -> str:
    """The record's spectral peaks (the decision's, its drive's lines left out) at which the
    identifier published no mode though it published modes at weaker ones (``found_hz``: their
    frequencies; a peak weaker than every one with a mode may be the noise's), in words, with
    the window's correlation times of the lowest of them and the option that helps; '' when
    there is none (a mode is at a peak within :data:`..core.identity.MATCH_TOL` and a bin of the
    decision's spectrum, 1 / :data:`..core.choice.SEGMENT_S` Hz), or without a decision, a
    driven run, or a mode (:func:`explain_no_estimate` says why then). A periodic drive's lines
    (the configuration's and the decision's) are no modes."""
    found = np.asarray(found_hz, dtype=float)
    if d is None or config.excitation != 'ambient' or not len(found):
        return ''
    lines = np.asarray((*(config.lines_hz or ()), *d.lines_hz), dtype=float)
    band = config.band_hz or (0.0, math.inf)
    missing, weaker = [], []  # (the peaks, strongest first)
    for p in d.peaks_hz:
        near = MATCH_TOL * p + 1.0 / SEGMENT_S  # (a peak's frequency: the spectrum's bin)
        if not band[0] <= p <= band[1] or np.any(np.abs(lines - p) <= near):
            continue
        if np.any(np.abs(found - p) <= near):
            missing, weaker = missing + weaker, []  # a mode at a weaker peak than these
        else:
            weaker.append(p)
    if not missing:
        return ''
    peaks = ', '.join(f'{p:.3g}' for p in missing)
    text = (
        f'no mode at the spectral peak(s) {peaks} Hz of the record (strongest first): a peak is '
        f'published once its poles stand stable over the model orders in {CONFIRM} analyses '
        f'running ({beside_analyses(config.ambient_window_s)} beside a stronger mode)'
    )
    advice = peak_window_advice(config.ambient_window_s, min(missing), '--ambient-window-s ')
    if advice:
        return f'{text}; {advice}'
    return text + ', which a sinusoid (a machine) or coloured noise does not'


def short_window(config: EstimatorConfig, d: Optional[Decision]) -> str:
    """Why no window was analysed: the record is shorter than one, or one holds fewer samples
    than the identifier needs (:data:`..core.ambient.MIN_WINDOW_SAMPLES`), with the window that
    would do."""
    window = config.ambient_window_s
    if d is not None and math.isfinite(d.rate_hz) and d.span_s >= window:
        need = math.ceil(MIN_WINDOW_SAMPLES / d.rate_hz)
        return (
            f'a {window:g} s window holds {window * d.rate_hz:.0f} samples at {d.rate_hz:.3g} Hz, '
            f'fewer than the identifier needs ({MIN_WINDOW_SAMPLES}): --ambient-window-s {need}'
        )
    text = f'the record is shorter than one window (--ambient-window-s {window:g}'
    if d is not None and math.isfinite(d.span_s):
        text += f'; it spans {d.span_s:.3g} s: a shorter window, at the cost of precision'
    return text + ')'


def read_ahead(
    blocks: Iterable[Tuple[np.ndarray, np.ndarray]],
) -> Tuple[Optional[Tuple[np.ndarray, np.ndarray]], Iterator[Tuple[np.ndarray, np.ndarray]]]:
    """The samples ``(t, y)`` of a stream's first :data:`..core.choice.DECIDE_S` s (None if it
    has none) and every block, the ones read ahead first (memory: those seconds only)."""
    blocks = iter(blocks)
    ahead = []
    for t, y in blocks:
        if not len(t):
            continue
        ahead.append((t, y))
        if float(t[-1]) - float(ahead[0][0][0]) >= DECIDE_S:
            break
    if not ahead:
        return None, blocks
    samples = tuple(np.concatenate([b[i] for b in ahead]) for i in (0, 1))
    return samples, itertools.chain(ahead, blocks)


def prepare(
    args, config: EstimatorConfig, t, y, channels: int, prog: str
) -> Tuple[EstimatorConfig, Decision, list[str]]:
    """The configuration a command line and a record ``(t, y)`` give (the default decided from
    the record: :func:`decides`), the decision, and the lines to print once the record has been
    estimated (what was decided, or a contradiction). The decision's ``offset``, when finite, is
    to be removed from the samples the configuration estimates (not otherwise)."""
    d = decide(t, y, channels, config.ambient_window_s, given=config.lines_hz or ())
    if d.model and (not decides(args) or periods_given(args) or model_given(args)):
        kept = '; --model, --band-hz or --min-periods given: the record as read, their model'
        d = dataclasses.replace(d, model='', offset=math.nan, reason=d.reason + kept)
    if decides(args):
        kept = (window_given(args), periods_given(args), damping_given(args))
        config, line = decided_config(config, d, prog, *kept)
        return config, d, [line]
    if getattr(args, 'paper', False):
        return config, d, []  # the paper's configuration, as printed
    warning = contradiction(config, d, prog)
    return config, d, [warning] if warning else []


def tracker_silence(counters) -> str:
    """Why the mode tracker published nothing, from its counters (:mod:`..core.modes`)."""
    held = {k: v for k, v in counters.items() if v and k.startswith('rejected_')}
    seen = ', '.join(f'{k}={v}' for k, v in held.items())
    if not counters.get('modes_found', 0):
        return (
            'the mode tracker found no mode: no pole stood above the noise and lasted ('
            + (seen or 'none even a candidate')
            + '): the record may hold no vibration above its noise (a sensor at rest); if it '
            'does, --band-hz around the mode, or --excitation ambient for a driven structure'
        )
    return (
        f'the mode tracker found {counters["modes_found"]} mode(s) and lost them before they '
        f'published ({seen or "no rejection"}): a frequency that moves, or poles of the noise; '
        'try --band-hz around the mode'
    )


def explain_no_estimate(
    counters, open_samples: Optional[int], config: EstimatorConfig, d: Optional[Decision] = None
) -> str:
    """Why a run gave no estimate, from its counters (and the record's decision ``d``: its
    spectrum), and what to try."""
    if counters.get('used', 0) == 0:
        return 'no sample was usable (see the skipped_* counters)'
    analyses, flat = counters.get('analyses', 0), counters.get('flat_windows', 0)
    if analyses and flat == analyses:
        return f'the signal is constant (every window analysed was flat: flat_windows={flat})'
    if is_noise(d):  # whatever the excitation
        return window_advice(config, d)
    if config.excitation == 'ambient':
        if not analyses:
            return short_window(config, d)
        advice = window_advice(config, d)
        if config.lines_hz:  # its modes dropped at a periodic drive's lines
            advice = (
                f'the identifier drops its modes at the {len(config.lines_hz)} lines of a '
                'periodic drive (lines_hz); where every peak is such a line (a train of impacts '
                'on one mode, its response at their harmonics) --excitation free reads each decay'
                + (f'; {advice}' if advice else '')
            )
        return (
            f'no mode stood out of the noise, stable over the model orders and in consecutive '
            f'windows, in {analyses} analyses: '
            + (
                advice
                or 'try --band-hz around the modes of interest or a longer --ambient-window-s'
            )
        )
    if config.modes:  # the mode tracker (its counters: core.modes)
        return tracker_silence(counters)
    held = {k: v for k, v in counters.items() if v and k.startswith('rejected_')}
    if set(held) == {'rejected_at_rest'}:
        rest = held['rejected_at_rest']
        return (
            f'the signal is at rest: every segment was flat (rejected_at_rest={rest}: no '
            f'variance, or a half range at most --min-amplitude {config.min_amplitude:g}): a '
            'constant signal, or the wrong column or topic'
        )
    if held:
        return (
            'every converged estimate was held back by the quality gate ('
            + ', '.join(f'{k}={v}' for k, v in held.items())
            + '): check --min-fit, --max-damping, --min-amplitude, --consistency (0: off, '
            'for a frequency that moves from one segment to the next), or the model (--model)'
        )
    text = 'the convergence test (Eqs. 16-17) never fired'
    if open_samples:
        text += f' (the last segment ran {open_samples} samples without converging'
        text += (
            ', '
            + (
                'max_window automatic: 10 s'
                if not config.max_window
                else f'max_window {config.max_window:g} s'
            )
            + ')'
        )
    return (
        text + f': the signal may not follow --model {config.model} (a decay: try '
        '--model damped-sinusoid), or try a larger --tolerance or a longer recording'
    )
