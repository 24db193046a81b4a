"""Several modes at once (``modes`` >= 1): find up to K modes and track each with its own estimator.

INTERFACE PLACEHOLDER (to be replaced by the multi-mode implementation): the class below already has
the interface the node, ``analyze`` and ``survey`` use, but it runs one estimator on the whole signal
and calls what it finds mode 1.

Interface:

* ``create_estimator(config)`` -- a :class:`FrequencyEstimator` when ``config.modes == 0``, else a
  :class:`ModeTracker`.
* ``ModeTracker.update(t, y) -> List[Estimate]`` (each with ``mode`` >= 1, 1 = the lowest
  frequency), ``process(t, y) -> EstimateArrays`` (with the ``mode`` column, sorted by time),
  ``counters`` (aggregate, the names of ``COUNTER_NAMES`` plus the mode finder's own),
  ``mode_counters() -> Dict[int, Dict[str, int]]``, ``status() -> List[ModeStatus]``, ``reset()``,
  ``restart()``, ``config``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Dict, List, Sequence, Union

from .config import EstimatorConfig
from .estimator import Estimate, EstimateArrays, FrequencyEstimator


@dataclass(frozen=True)
class ModeStatus:
    """What the tracker knows of one mode now."""

    mode: int
    frequency_hz: float       # last published frequency (NaN before the first)
    last_t: float             # stamp of that estimate (NaN before the first)
    band_hz: tuple            # the band its estimator runs on


class ModeTracker:
    """Find and track up to ``config.modes`` modes (placeholder: one estimator, mode 1)."""

    def __init__(self, config: EstimatorConfig):
        config.validate()
        self._config = config
        self._est = FrequencyEstimator(config.replace(modes=0))
        self._last = (float('nan'), float('nan'))

    @property
    def config(self) -> EstimatorConfig:
        return self._config

    def update(self, t: float, y: float) -> List[Estimate]:
        e = self._est.update(t, y)
        if e is None:
            return []
        e = Estimate(**{**e.__dict__, 'mode': 1})
        self._last = (e.frequency_hz, e.t)
        return [e]

    def process(self, t: Sequence[float], y: Sequence[float]) -> EstimateArrays:
        arrays = self._est.process(t, y)
        arrays.mode[:] = 1
        return arrays

    @property
    def counters(self) -> Dict[str, int]:
        return self._est.counters

    def mode_counters(self) -> Dict[int, Dict[str, int]]:
        return {1: self._est.counters}

    def status(self) -> List[ModeStatus]:
        return [ModeStatus(1, self._last[0], self._last[1], self._config.band_hz)]

    def reset(self) -> None:
        self._est.reset()

    def restart(self) -> None:
        self._est.restart()


def create_estimator(config: EstimatorConfig) -> Union[FrequencyEstimator, ModeTracker]:
    """The estimator of a configuration: one estimator (``modes`` = 0) or a mode tracker."""
    return FrequencyEstimator(config) if config.modes == 0 else ModeTracker(config)
