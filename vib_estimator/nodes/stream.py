# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The estimator node's processing without ROS (no rclpy; tested alone).

:class:`EstimatorStream` holds what the node does between a converted message and a publication:
the stamp time base (``t = seconds_since(stamp, first stamp)``, exactly as the offline
``vib-estimator analyze``), the estimator of the live configuration (``create_estimator``: one
:class:`~vib_estimator.core.FrequencyEstimator`, or a mode tracker with ``modes`` >= 1; replaced
on a change of configuration, its counters kept), and the :class:`~.health.Health` bookkeeping.
With several ``channels`` (the node's ``components``) the estimator is the joint identifier
(:func:`~vib_estimator.core.multichannel_free.create_joint_estimator`: free decays or
``excitation`` ambient, :func:`check_channels`): each sample is a tuple of values, each estimate a
:class:`~vib_estimator.core.multichannel.JointEstimate` (the estimate and its mode shape).

Warm-up. A configuration whose kernels are not compiled in this process yet (the first start, or a
change to a configuration that runs other kernels) is built in a background thread
(:func:`~vib_estimator.core.warmup.warm`: seconds from numba's cache, tens of seconds on a first
start after an install). Meanwhile :attr:`EstimatorStream.ready` is False, the node stays live
(services, diagnostics) and :meth:`EstimatorStream.hold` keeps the samples that arrive, in order,
up to :data:`WARMUP_BUFFER` (the oldest beyond it are dropped and counted in ``dropped_warmup``);
:meth:`EstimatorStream.poll` installs the estimator once it is built and feeds it the held samples,
a slice of at most its ``budget_s`` seconds a call (the node's single thread answers its services
and publishes its diagnostics between slices; a minute of input held took seconds to feed at
once); samples that arrive meanwhile are held behind them, and :attr:`EstimatorStream.ready`
turns True once none is left.
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from functools import partial
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

from ..core.choice import WATCH_S, DrivenWatch
from ..core.config import EstimatorConfig
from ..core.estimator import COUNTER_NAMES, Estimate, as_estimates
from ..core.modes import create_estimator
from ..core.multichannel import MIN_CHANNELS
from ..core.multichannel_free import JOINT_EXCITATIONS, create_joint_estimator
from ..core.warmup import is_warm, warm
from ..io.fields import seconds_since
from .health import WARN, Health, Status
from .self_test import self_test

#: the core counters while no estimator runs (a warm-up): nothing received yet
_IDLE_COUNTERS = dict.fromkeys(COUNTER_NAMES, 0)
#: samples held while the kernels compile: a minute at 1 kHz (a cold compile takes seconds)
WARMUP_BUFFER = 60_000
#: significant digits of the measured sampling rate the self-test's tones are made for (a rate
#: that wanders in its last digits gives the same tones, and the kept result)
SELF_TEST_DIGITS = 3
#: the diagnostics message while the kernels compile
WARMUP_MESSAGE = 'compiling estimator kernels (first start)'


def check_channels(channels: Sequence[str], config: EstimatorConfig) -> None:
    """ValueError unless ``config`` can identify ``channels`` (names): several need
    ``excitation`` free or ambient (a joint estimator,
    :func:`~vib_estimator.core.multichannel_free.create_joint_estimator`)."""
    if len(channels) >= MIN_CHANNELS and config.excitation not in JOINT_EXCITATIONS:
        raise ValueError(
            f'{len(channels)} components ({", ".join(channels)}) need excitation free or '
            f'ambient (a joint estimation), got excitation {config.excitation}: it takes one '
            'component'
        )


def estimator_factory(channels: Sequence[str]) -> Callable[[EstimatorConfig], Any]:
    """What builds the estimator of a configuration for ``channels``: one channel,
    :func:`~vib_estimator.core.modes.create_estimator`; several, the joint identifier."""
    if len(channels) < MIN_CHANNELS:
        return create_estimator
    return partial(create_joint_estimator, channels=tuple(channels))


class _Build:
    """An estimator of ``config`` built in a daemon thread (its kernels compiled first)."""

    def __init__(self, config: EstimatorConfig, create: Callable[[EstimatorConfig], Any]):
        self.config = config
        self._create = create
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
            self.estimator = self._create(self.config)
        except Exception as err:  # reported by the node, never lost in a thread
            self.error = err
        self.seconds = time.monotonic() - self.started

    @property
    def done(self) -> bool:
        return not self._thread.is_alive()


class EstimatorStream:
    """Samples in, estimates out, with the node's counters and status (see the module doc).

    ``background``: build an estimator whose kernels are not compiled yet in a thread (the node);
    False builds it at once (tests, tools). ``channels``: the names of the input's channels (the
    node's components); one (or none given) is the single-channel estimator, bit for bit; several
    feed :meth:`feed` a tuple of values a sample and give
    :class:`~vib_estimator.core.multichannel.JointEstimate` s (``excitation`` free or ambient).
    """

    def __init__(
        self,
        config: EstimatorConfig,
        now: float,
        background: bool = False,
        channels: Sequence[str] = (),
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
        #: seconds the last warm-up took (None before one ended), samples held when it ended
        self.warmup_seconds: Optional[float] = None
        self.warmup_held = 0
        #: whether the input looks driven throughout (a hint when the estimator is free's)
        self._watch = DrivenWatch()
        self.configure(config)

    @property
    def config(self) -> EstimatorConfig:
        """The live configuration (the one being built during a warm-up)."""
        return self._config

    @property
    def ready(self) -> bool:
        """False while a configuration's kernels compile and until the samples held meanwhile
        are fed (samples are held, not estimated)."""
        return self._build is None and not self._held

    def configure(self, config: EstimatorConfig, channels: Optional[Sequence[str]] = None) -> None:
        """A fresh estimator of ``config`` (a new segment, same time origin, counters kept) for
        ``channels`` (default: the same); built in the background when its kernels are not
        compiled yet and ``background`` was asked. ValueError if ``config`` cannot take the
        channels (:func:`check_channels`)."""
        channels = self.channels if channels is None else tuple(channels)
        check_channels(channels, config)
        self.channels = channels
        create = estimator_factory(channels)
        if self.estimator is not None:
            self.health.absorb(self.estimator.counters)
            self.estimator = None
        self._config = config
        self.health.forget_modes(config.modes)
        if self._background and not is_warm(config):
            self._build = _Build(config, create)
        else:
            self._install(create(config))

    def _install(self, estimator) -> None:
        self.estimator = estimator
        self._update = estimator.update  # bound once: the data path's one call
        self._build = None

    def feed(self, stamp_ns: int, value: float) -> Sequence[Estimate]:
        """One sample (stamp in integer ns); the estimates it completes (usually none).
        Only while :attr:`ready` (see :meth:`hold`)."""
        if self.origin is None:
            self.origin = stamp_ns
        self.last_t = t = seconds_since(stamp_ns, self.origin)
        self._watch.update(t, value if isinstance(value, float) else value[0])
        estimates = as_estimates(self._update(t, value))
        for e in estimates:
            self._watch.follow(getattr(e, 'estimate', e).frequency_hz)
        return estimates

    @property
    def held_samples(self) -> int:
        """Samples held, waiting for the end of the warm-up."""
        return len(self._held)

    def warmup_elapsed(self, now: float) -> float:
        """Seconds since the running warm-up started (0 when ready)."""
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
        """The core counters since start (across configurations) and the node's own."""
        core = self.estimator.counters if self.estimator is not None else _IDLE_COUNTERS
        return self.health.totals(core)

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
            now, self.counters, self.last_t, config.band_hz, config.modes, self._driven_hint()
        )
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
        share = self._watch.driven()
        if share is None or self.config.excitation != 'free':
            return None
        return (
            f'the input looks driven ({100 * share:.0f} % of the energy of the last '
            f'{WATCH_S:g} s): free-decay estimates of a driven structure scatter; '
            'excitation:=ambient identifies its modes (auto: both, per stretch)'
        )

    def reset(self) -> Tuple[bool, str]:
        """Start a new segment at the last sample; counters kept. (False, why) during a warm-up."""
        if not self.ready:
            return False, f'not ready: {WARMUP_MESSAGE}; the held samples start the first segment'
        self.estimator.reset()
        return True, 'new segment started'

    def self_test(self) -> Tuple[bool, str]:
        """:func:`~.self_test.self_test` of the live configuration at the input's sampling rate
        (to :data:`SELF_TEST_DIGITS` significant digits); (False, busy) during a warm-up.

        The tones are seeded, so the result is a function of (configuration, rate): it is kept,
        and a burst of calls costs one run, not one each -- the data path, which shares the node's
        single executor thread, is held up once."""
        if not self.ready:
            return False, f'busy: {WARMUP_MESSAGE}'
        rate = self.health.sample_rate_hz
        if math.isfinite(rate) and rate > 0:
            rate = float(f'{rate:.{SELF_TEST_DIGITS}g}')
        key = (self.config, rate if math.isfinite(rate) else None)
        if self._self_test[0] != key:
            self._self_test = (key, self_test(self.config, rate))
        return self._self_test[1]
