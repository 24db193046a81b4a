# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Mode identity over time: what counts as the same mode, written once for every estimator.

A :class:`ModeRegister` holds the modes an estimator knows (:class:`Mode`: last frequency, last
shape with several channels, last-seen time). Every estimate (``excitation = auto``, the joint
free-decay estimator) or every window's modes (the output-only identifier, one channel or
several) go through it:

1. **Match** (:meth:`ModeRegister.match`): an observation continues the known mode nearest in
   frequency within :data:`MATCH_TOL` (relative) whose last shape it matches, MAC >=
   :data:`MAC_MATCH` (:func:`continues`; without shapes, or with one channel, every shape
   matches); published modes first; each mode continues one observation at most.
2. **Observe** (:meth:`ModeRegister.observe`): the mode takes the observation's frequency, shape
   and time (``mac``: the MAC with its previous shape, NaN for a new mode); an unmatched one is a
   new mode -- at most :data:`MAX_TRACKS` are known: a full register takes no new mode, or
   (``replace``) forgets its least recent one for it.
3. **Confirm and forget** (:meth:`ModeRegister.settle`, after each set of observations): a mode
   publishes once seen ``confirm`` times running (``confirm_beside`` while a stronger one is
   published, :meth:`ModeRegister.need`): 1 for estimates, which are published already;
   :data:`CONFIRM` and :data:`CONFIRM_BESIDE` for the identifier's windows, whose statistical
   poles come and go. An unpublished mode not seen is forgotten, a published one unseen for
   ``forget_s`` s too.
4. **Number** (:meth:`ModeRegister.number`): published modes are numbered by ascending frequency,
   1 = the lowest (the compiled mode tracker's ``mode`` key numbers its modes so too).

The compiled mode tracker (:mod:`.modes`) is apart: inside its kernel it matches single poles,
of windows from 0.7 of a period to a few periods, to its modes, not published estimates to
known modes; its tolerances (``modes.MATCH_TOL`` = 0.06, ``PENDING_TOL``, ``DUPLICATE_TOL``,
``LOSE_PERIODS``) are those poles', pinned by its own tests (test/core/test_modes.py).
"""

from __future__ import annotations

import math
from typing import Optional

from .shapes import mac

#: an observation continues a known mode within this relative frequency ...
MATCH_TOL = 0.03
#: ... if their shapes' MAC is at least this
MAC_MATCH = 0.5
#: consecutive analyses that must see a new mode before it publishes, while none is published
#: (the identifier's windows)
CONFIRM = 3
#: ... and beside published modes: a coloured excitation's continuum (a randomly commanded arm's)
#: gives statistical poles beside a strong mode that last 1-8 analyses; a mode persists
CONFIRM_BESIDE = 8
#: most modes known at once
MAX_TRACKS = 8


def continues(f: float, shape, frequency: float, last_shape) -> Optional[float]:
    """The relative frequency distance of a mode (``f``, ``shape``) from a known one
    (``frequency``, ``last_shape``) if it continues it -- within :data:`MATCH_TOL` and, both
    shapes given, with a MAC of at least :data:`MAC_MATCH` --, else None."""
    dist = abs(f / frequency - 1)
    if dist > MATCH_TOL:
        return None
    if shape is None or last_shape is None or mac(shape, last_shape) >= MAC_MATCH:
        return dist
    return None


class Mode:
    """A known mode: its last frequency, shape (None without) and time; ``seen``: the
    observations running that saw it; ``mac``: its last shape's MAC with the one before (NaN for
    its first); ``amplitude`` (ranks the strongest), ``estimates`` (published, its count)."""

    __slots__ = (
        'amplitude',
        'estimates',
        'frequency',
        'last_t',
        'mac',
        'published',
        'seen',
        'shape',
    )

    def __init__(self, frequency: float, t: float, shape=None):
        self.frequency, self.last_t, self.shape = frequency, t, shape
        self.seen, self.published, self.estimates = 0, False, 0
        self.amplitude, self.mac = 0.0, math.nan


class ModeRegister:
    """The known modes (module docstring). ``forget_s``: a published mode unseen this long is
    forgotten; ``confirm``, ``confirm_beside``: observations running before a new mode publishes
    (alone, beside a published one); ``replace``: a full register forgets its least recent mode
    for a new one (else takes none); ``new``: the :class:`Mode` class to make."""

    def __init__(
        self,
        forget_s: float = math.inf,
        confirm: int = 1,
        confirm_beside: int = 1,
        replace: bool = False,
        new=Mode,
    ):
        self.forget_s, self.confirm, self.confirm_beside = forget_s, confirm, confirm_beside
        self.replace, self.new = replace, new
        self.modes: list = []

    def clear(self) -> None:
        self.modes = []

    def match(self, frequencies, shapes=None) -> dict[int, Mode]:
        """Each observation's mode (by index; frequencies, and their shapes or None): the nearest
        it continues (:func:`continues`), published modes first, one observation a mode."""
        pairs = []
        for i, f in enumerate(frequencies):
            shape = None if shapes is None else shapes[i]
            for j, m in enumerate(self.modes):
                dist = continues(f, shape, m.frequency, m.shape)
                if dist is not None:
                    pairs.append((not m.published, dist, i, j))
        match: dict[int, Mode] = {}
        used = set()
        for _, _, i, j in sorted(pairs):
            if i not in match and j not in used:
                match[i] = self.modes[j]
                used.add(j)
        return match

    def observe(self, f: float, t: float, shape=None, mode: Optional[Mode] = None):
        """``mode`` (the observation's match, or None: a new mode) seen at ``f`` Hz at ``t`` with
        ``shape``; the mode, or None when the register is full and does not replace."""
        if mode is None:
            if len(self.modes) >= MAX_TRACKS:
                if not self.replace:
                    return None
                self.modes.remove(min(self.modes, key=lambda m: m.last_t))
            mode = self.new(f, t, shape)
            self.modes.append(mode)
        else:
            mode.mac = math.nan if shape is None else mac(shape, mode.shape)
        mode.frequency, mode.last_t, mode.shape = float(f), t, shape
        mode.seen += 1
        return mode

    def settle(self, seen, t: float, most: int = 0) -> tuple[list, int, int]:
        """After the observations at ``t`` (``seen``: the modes they saw): forget the unseen
        unpublished modes and the published ones unseen for ``forget_s``; publish those seen
        ``confirm`` times running (``confirm_beside`` beside a published one) and the published
        ones seen (the ``most`` strongest, if set). ``(the modes to publish now, new ones
        published, published ones forgotten)``."""
        lost = 0
        for m in list(self.modes):
            if m not in seen:
                m.seen = 0
                if not m.published or t - m.last_t > self.forget_s:
                    self.modes.remove(m)
                    lost += m.published
        strongest = max((m.amplitude for m in self.modes if m.published), default=-1.0)
        ready = [
            m
            for m in self.modes
            if m in seen and (m.published or m.seen >= self.need(m, strongest))
        ]
        if most:
            ready = sorted(ready, key=lambda m: -m.amplitude)[:most]
        found = sum(not m.published for m in ready)
        for m in ready:
            m.published = True
        return ready, found, lost

    def need(self, mode: Mode, strongest: float) -> int:
        """The observations running a new ``mode`` needs to publish, ``strongest`` the largest
        amplitude of the published modes (-1: none): ``confirm`` while none is published, or
        when it is at least as strong as the strongest published (a mode, not a
        statistical pole beside one: the 5 Hz mode of a 20 s record of 5 + 17 Hz, found after
        the weaker 17 Hz, was never published in the record's 9 analyses), else
        ``confirm_beside`` (amplitudes not set, 0: beside)."""
        if strongest < 0 or 0 < strongest <= mode.amplitude:
            return self.confirm
        return self.confirm_beside

    def number(self, mode: Mode) -> int:
        """A published mode's number: its rank by frequency among the published, 1 = the
        lowest."""
        return 1 + sum(m.published and m.frequency < mode.frequency for m in self.modes)

    def counters(self) -> dict[int, dict[str, int]]:
        """Each published mode's estimates, by its number (the mode tracker's
        ``mode_counters``)."""
        order = sorted((m for m in self.modes if m.published), key=lambda m: m.frequency)
        return {k: {'estimates': m.estimates} for k, m in enumerate(order, 1)}

    def observe_one(self, f: float, t: float, shape=None) -> Optional[Mode]:
        """One estimate (published at once): matched, observed and settled; its mode (None when
        the register is full and does not replace)."""
        match = self.match([f], None if shape is None else [shape]).get(0)
        mode = self.observe(f, t, shape, match)
        if mode is not None:
            self.settle({mode}, t)
        return mode
