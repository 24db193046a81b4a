"""The estimator node's processing without ROS (no rclpy; tested alone).

:class:`EstimatorStream` holds what the node does between a converted message and a publication:
the stamp time base (``t = seconds_since(stamp, first stamp)``, exactly as the offline
``vib-estimator analyze``), the estimator of the live configuration (``create_estimator``: one
:class:`~vib_estimator.core.FrequencyEstimator`, or a mode tracker with ``modes`` >= 1; replaced
on a change of configuration, its counters kept), and the :class:`~.health.Health` bookkeeping.
"""
from __future__ import annotations

from typing import Dict, Sequence, Tuple

from ..core.config import EstimatorConfig
from ..core.estimator import Estimate
from ..core.modes import create_estimator
from ..io.fields import seconds_since
from .health import Health, Status
from .self_test import self_test

_NONE: Tuple[Estimate, ...] = ()


class EstimatorStream:
    """Samples in, estimates out, with the node's counters and status (see the module doc)."""

    def __init__(self, config: EstimatorConfig, now: float):
        self.health = Health(now)
        self.origin = None     # first stamp, ns: t = 0
        self.last_t = None     # time of the last sample, s
        self.estimator = None
        self.configure(config)

    @property
    def config(self) -> EstimatorConfig:
        return self.estimator.config

    def configure(self, config: EstimatorConfig) -> None:
        """A fresh estimator of ``config`` (a new segment, same time origin, counters kept)."""
        if self.estimator is not None:
            self.health.absorb(self.estimator.counters)
        self.estimator = create_estimator(config)
        self._update = self.estimator.update     # bound once: the data path's one call
        self.health.forget_modes(config.modes)

    def feed(self, stamp_ns: int, value: float) -> Sequence[Estimate]:
        """One sample (stamp in integer ns); the estimates it completes (usually none)."""
        if self.origin is None:
            self.origin = stamp_ns
        self.last_t = t = seconds_since(stamp_ns, self.origin)
        result = self._update(t, value)
        if not result:     # None, or an empty list (modes >= 1)
            return _NONE
        return result if isinstance(result, list) else (result,)

    def published(self, estimate: Estimate, now: float) -> None:
        """``estimate`` was published at ``now`` (monotonic s)."""
        self.health.record(estimate, now, self.counters)

    @property
    def counters(self) -> Dict[str, int]:
        """The core counters since start (across configurations) and the node's own."""
        return self.health.totals(self.estimator.counters)

    def status(self, now: float) -> Status:
        """The diagnostics status at ``now`` (monotonic s)."""
        config = self.config
        return self.health.status(now, self.counters, self.last_t, config.band_hz, config.modes)

    def reset(self) -> None:
        """Start a new segment at the last sample; counters kept."""
        self.estimator.reset()

    def self_test(self) -> Tuple[bool, str]:
        """:func:`~.self_test.self_test` of the live configuration at the input's sampling rate."""
        return self_test(self.config, self.health.sample_rate_hz)
