# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The estimator node's processing without ROS (no rclpy; tested alone).

:class:`EstimatorStream` holds what the node does between a converted message and a publication:
the stamp time base (``t = seconds_since(stamp, first stamp)``, exactly as the offline
``vib-estimator analyze``), the estimator of the live configuration and channels
(:func:`~vib_estimator.core.create_estimator`; replaced on a change of configuration, its counters
kept), and the :class:`~.health.Health` bookkeeping. With several ``channels`` (the node's
``components``) the estimator is a joint one (:func:`check_channels`): each sample is a tuple of
values, each :class:`~vib_estimator.core.Estimate` carries its mode's shape.

Warm-up. A configuration whose kernels are not compiled in this process yet (the first start, or a
change to a configuration that runs other kernels) is built in a background thread
(:func:`~vib_estimator.core.warmup.warm`: seconds from numba's cache, tens of seconds on a first
start after an install). Meanwhile the node stays live (services, diagnostics), and:

- a configuration of the free-decay estimators on one channel (``excitation`` free, with or
  without ``band_hz`` and ``modes``: :func:`interpretable`, the default) estimates at once with
  its kernels uncompiled (:func:`~vib_estimator.core.factory.create_uncompiled`: the algebraic
  estimator's floats, about 100 us a sample; the mode tracker's within ~1e-9 relative):
  :attr:`EstimatorStream.ready` is True, and :meth:`EstimatorStream.poll` switches it to the
  compiled kernel once that is built, between two samples (:attr:`EstimatorStream.compiling` until
  then);
- any other (the ambient identifier, ``auto``, several channels) is not
  :attr:`EstimatorStream.ready`:
  :meth:`EstimatorStream.hold` keeps the samples that arrive, in order, up to
  :data:`WARMUP_BUFFER` (the oldest beyond it are dropped and counted in ``dropped_warmup``);
  :meth:`EstimatorStream.poll` installs the estimator once it is built and feeds it the held
  samples, a slice of at most its ``budget_s`` seconds a call (the node's single thread answers
  its services and publishes its diagnostics between slices; a minute of input held took seconds
  to feed at once); samples that arrive meanwhile are held behind them, and
  :attr:`EstimatorStream.ready` turns True once none is left.
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..core.choice import (
    DRIVEN_ABOVE,
    FREE_BELOW,
    WATCH_S,
    Decision,
    StreamChoice,
    decide,
    window_advice,
)
from ..core.config import EstimatorConfig
from ..core.estimator import COUNTER_NAMES, MIN_CHANNELS, Estimate
from ..core.factory import create_estimator, create_uncompiled, kind_of
from ..core.warmup import is_warm, warm
from ..io.fields import seconds_since
from ..io.heap import release_memory
from .health import WARN, Health, Status
from .self_test import in_process, self_test

#: the core counters while no estimator runs (a warm-up): nothing received yet
_IDLE_COUNTERS = dict.fromkeys(COUNTER_NAMES, 0)
#: samples held while the kernels compile: a minute at 1 kHz (a cold compile takes seconds)
WARMUP_BUFFER = 60_000
#: significant digits of the measured sampling rate the self-test's tones are made for (a rate
#: that wanders in its last digits gives the same tones, and the kept result)
SELF_TEST_DIGITS = 3
#: no samples to prime a new estimator with (:meth:`EstimatorStream.configure`)
NO_PRIMER = (np.empty(0), np.empty(0))
#: the free-decay window a stream's decision may replace (the configured default's)
DEFAULT_WINDOW = (EstimatorConfig().min_periods, EstimatorConfig().early_std_rel)
#: the diagnostics message while the kernels compile
WARMUP_MESSAGE = 'compiling estimator kernels (first start)'


def check_channels(channels: Sequence[str], config: EstimatorConfig) -> None:
    """ValueError unless ``config`` has an estimator for ``channels`` (the node's components:
    :func:`~vib_estimator.core.factory.kind_of`)."""
    what = f'{len(channels)} components ({", ".join(channels)})'
    kind_of(config, max(len(channels), 1), what)


def interpretable(config: EstimatorConfig, channels: Sequence[str]) -> bool:
    """Whether the estimator of ``config`` for ``channels`` can estimate while its kernels
    compile (with them uncompiled: :func:`~vib_estimator.core.factory.create_uncompiled`): the
    free-decay estimators on one channel, ``band_hz`` and ``modes`` included."""
    return kind_of(config, max(len(channels), 1)).uncompiled is not None


class _Build:
    """An estimator of ``config`` for ``channels`` built in a daemon thread (its kernels
    compiled first; only compiled when ``channels`` is None: the stream estimates uncompiled
    meanwhile)."""

    def __init__(
        self,
        config: EstimatorConfig,
        channels: Optional[Tuple[str, ...]],
        also: Tuple[EstimatorConfig, ...] = (),
    ):
        self.config = config
        self._channels = channels
        self._also = also  # configurations warmed after it (the estimator is built first)
        self.started = time.monotonic()
        self.seconds = 0.0
        self.estimator = None
        self.error: Optional[BaseException] = None
        self._thread = threading.Thread(
            target=self._run, name='vib_estimator warm-up', daemon=True
        )
        self._thread.start()

    def _run(self) -> None:
        try:
            warm(self.config)
            if self._channels is not None:
                self.estimator = create_estimator(self.config, self._channels)
            for config in self._also:
                warm(config)
        except Exception as err:  # reported by the node, never lost in a thread
            self.error = err
        self.seconds = time.monotonic() - self.started

    @property
    def done(self) -> bool:
        return not self._thread.is_alive()


class EstimatorStream:
    """Samples in, estimates out, with the node's counters and status (see the module doc).

    ``background``: build an estimator whose kernels are not compiled yet in a thread (the node);
    False builds it at once (tests, tools). ``deciding``: the caller asks :meth:`decision` and
    applies it (the node's ``decide_excitation``); else the status hints at a driven input.
    ``channels``: the names of the input's channels (the
    node's components); one (or none given) is the single-channel estimator, bit for bit; several
    feed :meth:`feed` a tuple of values a sample and give estimates with their ``shape``
    (``excitation`` free or ambient).
    """

    def __init__(
        self,
        config: EstimatorConfig,
        now: float,
        background: bool = False,
        channels: Sequence[str] = (),
        deciding: bool = False,
    ):
        config.validate()
        check_channels(channels, config)
        self.channels: Tuple[str, ...] = tuple(channels)
        self.health = Health(now)
        self.origin = None  # first stamp, ns: t = 0
        self.last_t = None  # time of the last sample, s
        self.estimator = None
        self._config = config
        self._background = background
        self._build: Optional[_Build] = None
        self._held: deque = deque()
        self._self_test: Tuple[Any, Tuple[bool, str]] = (None, (False, ''))
        #: the self-test running in a thread (:meth:`self_test` with ``wait`` False)
        self._self_test_run: Optional[_SelfTestRun] = None
        #: seconds the last warm-up took (None before one ended), samples held when it ended
        self.warmup_seconds: Optional[float] = None
        self.warmup_held = 0
        #: whether the input looks driven, and what it needs (core.choice.StreamChoice)
        self._choice = StreamChoice(max(1, len(self.channels)))
        #: the excitation was last set by :meth:`decision` (not by the user)
        self.decided = False
        #: stream time of the last estimate, or of the last configuration (:meth:`_silent_hint`)
        self._estimated_at: Optional[float] = None
        #: (stream time, advice) of the last :meth:`_silent_hint` computed
        self._advice: Tuple[float, str] = (-math.inf, '')
        #: the samples a new estimator is primed with (:meth:`configure`)
        self._primer: Tuple[np.ndarray, np.ndarray] = NO_PRIMER
        #: (stream time, seconds of input primed) of the last :meth:`configure` (:meth:`_waiting`)
        self._configured: Tuple[Optional[float], float] = (None, 0.0)
        #: :meth:`decision` is asked (the node's ``decide_excitation``): no hint, a switch
        self.deciding = deciding
        #: a configuration was built since the last :func:`release_memory` (the node's 1-s
        #: diagnostics give the C heap's free pages back then: an estimator built and primed, a
        #: storm of them, leave freed pages behind)
        self.trim_due = False
        self.configure(config)

    @property
    def config(self) -> EstimatorConfig:
        """The live configuration (the one being built during a warm-up)."""
        return self._config

    @property
    def ready(self) -> bool:
        """False while a configuration's kernels compile and it cannot estimate meanwhile, and
        until the samples held meanwhile are fed (samples are held, not estimated: see the module
        doc)."""
        return self.estimator is not None and not self._held

    @property
    def compiling(self) -> bool:
        """True while a configuration's kernels compile (estimating uncompiled meanwhile when
        :attr:`ready`)."""
        return self._build is not None

    def configure(
        self,
        config: EstimatorConfig,
        channels: Optional[Sequence[str]] = None,
        prime: bool = False,
    ) -> None:
        """A fresh estimator of ``config`` (a new segment, same time origin, counters kept) for
        ``channels`` (default: the same); built in the background when its kernels are not
        compiled yet and ``background`` was asked. ValueError if ``config`` cannot take the
        channels (:func:`check_channels`). ``prime`` (a :meth:`decision` applied): the new
        identifier (not ``free``), or mode tracker, is first fed the input's last seconds the
        decision read, uncounted and unpublished, so that a driven stream's window is not filled
        again from empty (a decay's modes go on being tracked)."""
        channels = self.channels if channels is None else tuple(channels)
        check_channels(channels, config)
        primes = (
            prime
            and channels == self.channels
            and (config.excitation != 'free' or config.modes > 0)
        )
        self._primer = self._choice.kept() if primes else NO_PRIMER
        primed = self._primer[0]
        self._configured = (self.last_t, float(primed[-1] - primed[0]) if len(primed) else 0.0)
        self.channels = channels
        self.trim_due = True
        if self.estimator is not None:
            self.health.absorb(self.estimator.counters)
            self.estimator = None
        self._config = config
        self._estimated_at = self.last_t
        self.health.forget_modes(config.modes)
        if self._background and not is_warm(config):
            if interpretable(config, channels):
                self._install(create_uncompiled(config, channels))
                self._build = _Build(config, None, self._decidable(config, channels))
            else:
                self._build = _Build(config, channels)
        else:
            self._install(create_estimator(config, channels))
        self.health.count_holds_from(self.counters)

    def _decidable(self, config: EstimatorConfig, channels: Tuple[str, ...]) -> tuple:
        """The identifier a deciding stream on one channel may switch to (``auto``), to be
        warmed in the start's build: its code (the correlations' kernel, ``scipy.signal``'s
        filter design) then loads before the first estimate, not at the first switch, in the
        data path, minutes into a run (3.5 MB of RSS, docs/soak.md)."""
        one = len(channels) < MIN_CHANNELS and config.excitation == 'free'
        return (config.replace(excitation='auto'),) if self.deciding and one else ()

    def _install(self, estimator) -> None:
        self.estimator = estimator
        self._update = estimator.update  # bound once: the data path's one call
        self._build = None
        if len(self._primer[0]):  # fed before any held sample; its counts taken back
            estimator.process(*self._primer)  # (streaming equals batch)
            self.health.absorb({name: -n for name, n in estimator.counters.items()})
            self._primer = NO_PRIMER

    def feed(self, stamp_ns: int, value: float) -> Sequence[Estimate]:
        """One sample (stamp in integer ns); the estimates it completes (usually none).
        Only while :attr:`ready` (see :meth:`hold`)."""
        if self.origin is None:
            self.origin = stamp_ns
        self.last_t = t = seconds_since(stamp_ns, self.origin)
        self._choice.update(t, value)
        estimates = self._update(t, value)
        if not estimates:
            return estimates
        tested = self._tests_free_decay()
        kept = []
        for e in estimates:
            self._choice.follow(e.frequency_hz)
            if tested and self._choice.free_decay(e.frequency_hz) is False:
                self.health.count('not_free_decay')
                continue
            self._estimated_at = t
            kept.append(e)
        return kept

    def _tests_free_decay(self) -> bool:
        """Whether each free estimate must pass the free-decay test to be published
        (:meth:`~vib_estimator.core.choice.StreamChoice.free_decay`, as ``auto`` tests its free
        stretches): while the node decides its excitation and runs the algebraic estimator on
        one channel (``excitation`` free, no ``modes``, no ``band_hz``), so that a driven input
        gets no free-decay estimates of no mode before the decision (its first 20-60 s)."""
        config = self._config
        return (
            self.deciding
            and config.excitation == 'free'
            and config.modes == 0
            and config.band_hz is None
            and len(self.channels) < MIN_CHANNELS
        )

    @property
    def held_samples(self) -> int:
        """Samples held, waiting for the end of the warm-up."""
        return len(self._held)

    def warmup_elapsed(self, now: float) -> float:
        """Seconds since the running warm-up started (0 when compiled)."""
        return 0.0 if self._build is None else now - self._build.started

    def hold(self, stamp_ns: int, value: float, tag: Any = None) -> bool:
        """Keep a sample that arrived during a warm-up, with ``tag`` (the node's header), until
        :meth:`poll`; True when this is the first sample dropped (the buffer is full: the oldest
        goes), so the caller can warn once."""
        held = self._held
        held.append((stamp_ns, value, tag))
        if len(held) > WARMUP_BUFFER:
            held.popleft()
            return self.health.count('dropped_warmup') == 1
        return False

    def poll(self, budget_s: float = math.inf) -> Optional[List[Tuple[Any, Sequence[Estimate]]]]:
        """None while the warm-up goes on (or when nothing is held); once it has ended, install
        the estimator, feed it the held samples in order for up to ``budget_s`` seconds (at least
        one), and return the (tag, estimates) of those that completed estimates. Call again until
        :attr:`ready` (samples held after this call wait behind those left). Raises the build's
        error if it failed."""
        build = self._build
        if build is not None:
            if not build.done:
                return None
            if build.error is not None:
                self._build = None
                raise build.error
            self.warmup_seconds = build.seconds
            if build.estimator is None:  # estimating uncompiled meanwhile: the compiled kernel now
                self._build = None
                self.estimator.compiled()
                return []
            self.warmup_held = len(self._held)
            self._install(build.estimator)
        elif not self._held:
            return None
        held, feed, clock = self._held, self.feed, time.monotonic
        deadline = clock() + budget_s
        out = []
        while held:
            stamp_ns, value, tag = held.popleft()
            estimates = feed(stamp_ns, value)
            if estimates:
                out.append((tag, estimates))
            if clock() >= deadline:
                break
        return out

    def published(self, estimate: Estimate, now: float) -> None:
        """``estimate`` was published at ``now`` (monotonic s)."""
        self.health.record(estimate, now, self.counters)

    @property
    def counters(self) -> Dict[str, int]:
        """The core counters since start (across configurations) and the node's own;
        ``estimates``: those published (the core's, less those the free-decay test held back,
        ``not_free_decay``)."""
        core = self.estimator.counters if self.estimator is not None else _IDLE_COUNTERS
        totals = self.health.totals(core)
        totals['estimates'] = (
            totals.get('estimates', 0) - self.health.node_counters['not_free_decay']
        )
        return totals

    def status(self, now: float) -> Status:
        """The diagnostics status at ``now`` (monotonic s)."""
        if not self.ready:
            values: Dict[str, object] = {
                'warmup_s': self.warmup_elapsed(now),
                'held_samples': self.held_samples,
                **self.counters,
            }
            return Status(WARN, WARMUP_MESSAGE, values)
        config = self.config
        status = self.health.status(
            now,
            self.counters,
            self.last_t,
            config.band_hz,
            config.modes,
            self._driven_hint() or self._silent_hint(),
            self._waiting(),
        )
        if self.compiling:  # estimating uncompiled meanwhile
            status.values['warmup_s'] = self.warmup_elapsed(now)
        if len(self.channels) >= MIN_CHANNELS:  # a joint identification: which channels
            status.values['channels'] = ','.join(self.channels)
        return status

    def restart(self) -> None:
        """Forget the signal (a jump of the stamps): the next sample starts afresh, uncompared
        with the last; counters kept. Nothing during a warm-up (the held samples go on)."""
        if self.ready:
            self.estimator.restart()

    def _driven_hint(self) -> Optional[str]:
        """With the free-decay estimator, what to say when the input looks driven throughout
        (:class:`~vib_estimator.core.choice.DrivenWatch`); else None."""
        # deciding: driven now and in part (a structure moved between driven stretches), and
        # decide() tells ambient from auto; else driven throughout is what the hint says
        share = self._choice.driven(FREE_BELOW if self.deciding else DRIVEN_ABOVE)
        if share is None or self.config.excitation != 'free' or self.deciding:
            return None
        span = min(self._choice.watch.span, WATCH_S)
        return (
            f'the input looks driven ({100 * share:.0f} % of the energy of the last {span:.0f} '
            's): free-decay estimates of a driven structure scatter; '
            'excitation:=ambient identifies its modes (auto: both, per stretch)'
        )

    def _waiting(self) -> Optional[str]:
        """Under the identifier (``excitation`` ambient or auto), before its first estimate since
        it was configured and while its window is not full yet: how much of it it holds (the
        input primed at a decision, and since); else None."""
        config = self.config
        at, primed = self._configured
        if config.excitation == 'free' or self.last_t is None or self._estimated_at != at:
            return None
        held = primed + self.last_t - (at or 0.0)
        if held >= config.ambient_window_s:
            return None
        return (
            f'identifying the modes (excitation {config.excitation}): {held:.0f} s of its '
            f'{config.ambient_window_s:g} s window held, the first estimate when it is full'
        )

    def _silent_hint(self) -> Optional[str]:
        """Under the identifier (``excitation`` ambient or auto), when it published nothing for
        two windows (and a minute): why, from the spectrum of the input's last seconds -- the
        window's correlation times of their lowest peak and the ``ambient_window_s`` that holds
        enough (:func:`~vib_estimator.core.choice.window_advice`), computed at most every
        :data:`~vib_estimator.core.choice.WATCH_S` / 2 s of stream; else None."""
        config = self.config
        since = self._estimated_at if self._estimated_at is not None else 0.0
        if config.excitation == 'free' or self.last_t is None:
            return None
        silent = self.last_t - since
        if silent < max(2 * config.ambient_window_s, 60.0):
            return None
        at, advice = self._advice
        if self.last_t - at >= WATCH_S / 2 or self.last_t < at:
            t, y = self._choice.kept()
            d = decide(t, y, max(1, len(self.channels)), config.ambient_window_s, stream=True)
            advice = window_advice(config.ambient_window_s, d, 'ambient_window_s:=')
            self._advice = (self.last_t, advice)
        if not advice:
            return None
        return f'no mode for {silent:.0f} s: {advice}'

    def decision(self) -> Optional[Decision]:
        """What the input needs now, if not what runs (``decide_excitation``; after
        :meth:`status`, which watches the input): from ``free``, once the input looks driven
        (now, and for over :data:`~vib_estimator.core.choice.FREE_BELOW` of its last seconds'
        energy), analyze's decision over those seconds (excitation and ambient window), or
        when its estimator stays silent on a ringing input or a decay's modes ring on, a decay
        of several modes (``modes``);
        from an ``ambient`` decided so, ``auto`` once it looks free again
        (:class:`~vib_estimator.core.choice.StreamChoice`). The caller applies it (the node: as
        its parameters) and sets :attr:`decided`."""
        if not self.ready:
            return None
        config = self.config
        windowed = (config.min_periods, config.early_std_rel) != DEFAULT_WINDOW
        return self._choice.decision(
            config.excitation, self.decided, config.ambient_window_s, config.modes, windowed
        )

    def reset(self) -> Tuple[bool, str]:
        """Start a new segment at the last sample; counters kept. (False, why) during a warm-up."""
        if not self.ready:
            return False, f'not ready: {WARMUP_MESSAGE}; the held samples start the first segment'
        self.estimator.reset()
        return True, 'new segment started'

    def self_test(self, wait: bool = True) -> Optional[Tuple[bool, str]]:
        """:func:`~.self_test.self_test` of the live configuration at the input's sampling rate
        (to :data:`SELF_TEST_DIGITS` significant digits); (False, busy) during a warm-up.

        The tones are seeded, so the result is a function of (configuration, rate): it is kept,
        and a burst of calls costs one run, not one each. The run is in a thread of its own
        (:class:`_SelfTestRun`), the tones in a process of their own
        (:func:`~.self_test.in_process`: their memory never the node's): ``wait`` False returns
        None while it runs (call again: its result once done), so that the node's executor
        thread, which carries the data path, the diagnostics and the other services, is never
        held by it (under the identifier, three tones over three windows of 89 s: 0.9 CPU s,
        which held /diagnostics silent for 3.8-5.2 s on a loaded machine). One run at a time: a
        call while one runs gets that run's result, whatever changed since it began, and the
        next call tests what is live then (a run replaced at each change of the key never
        finished, and the calls waiting for it were never answered: the input's rate moved
        with each fault; it is kept over one now: :data:`.health.RATE_UPSETS`).
        While the kernels compile the tones run uncompiled only for the
        algebraic estimator without ``band_hz`` (0.1 CPU s): with ``band_hz`` (0.5 CPU s) or the
        mode tracker (0.9), sharing Python's lock with the compile, they held the data path up
        for seconds (21 s on a loaded machine): busy."""
        if not self.ready or (self.compiling and (self.config.band_hz or self.config.modes)):
            return False, f'busy: {WARMUP_MESSAGE}'
        rate = self.health.sample_rate_hz
        if math.isfinite(rate) and rate > 0:
            rate = float(f'{rate:.{SELF_TEST_DIGITS}g}')
        key = (self.config, rate if math.isfinite(rate) else None)
        run = self._self_test_run
        if run is None:
            if self._self_test[0] == key:
                return self._self_test[1]
            create = create_uncompiled if self.compiling else None  # the same result
            run = self._self_test_run = _SelfTestRun(key, create)
        if not run.finished.wait(None if wait else 0.0):
            return None
        self._self_test, self._self_test_run = (run.key, run.result), None
        return run.result


class _SelfTestRun:
    """:func:`~.self_test.self_test` of ``key`` (configuration, rate) in a daemon thread (numpy
    and the kernels let the caller's thread run meanwhile: it waited 14 ms at most in a run of
    the identifier's tones); :attr:`finished` is set once :attr:`result` is in."""

    def __init__(self, key: Tuple[EstimatorConfig, Optional[float]], create):
        self.key = key
        self.result: Tuple[bool, str] = (False, '')
        self.finished = threading.Event()
        self._create = create
        threading.Thread(target=self._run, name='vib_estimator self test', daemon=True).start()

    def _run(self) -> None:
        try:
            self.result = self._tones()
        except Exception as err:  # answered, never lost in a thread
            self.result = (False, f'FAILED: the self test raised {err!r}')
        release_memory()
        self.finished.set()

    def _tones(self) -> Tuple[bool, str]:
        """The tones in a process of their own (:func:`~.self_test.in_process`), or here when
        none could run (said in the answer); here, uncompiled, while the kernels compile."""
        if self._create is not None:
            return self_test(*self.key, self._create)
        result = in_process(*self.key)
        if result is None:
            ok, text = self_test(*self.key)
            result = ok, text + ' (run in the node: no process of its own)'
        return result
