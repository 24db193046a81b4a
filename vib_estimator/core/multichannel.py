# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Several channels, one set of modes: the output-only identifier with mode shapes.

``excitation = ambient`` with two or more channels (several accelerometers, the three axes of an
IMU, the joints of an arm): the modes are identified jointly from all channels' output
correlations, each with its **shape** -- how much, and in which phase, each channel moves in it.
It is the identifier of one channel (:mod:`.ambient`, whose m = 1 case that is) with its shapes
given out: the SSI-cov of the correlation matrices (:mod:`.ssi`, every channel a reference, the
block rows :func:`.ssi.block_rows`), each mode's shape and its uncertainty (the spread over the
stable model orders), close clusters merged only when their shapes agree (MAC >=
:data:`.ssi.MAC_SAME`), a mode kept when it stands above the noise on at least one channel, its
bound and frequency refinement on that channel (:mod:`.whittle`), and its identity over time by
frequency and shape (:mod:`.identity`).

Interface: :class:`JointAmbientEstimator` ``(config, channels)`` ``.process(t, Y) ->``
:class:`JointEstimates` (``Y``: samples x channels), ``.update(t, y) -> list[Estimate]``,
``.counters``, ``.reset()``, ``.restart()``, ``.config``, ``.channels``.

Each estimate: an :class:`..estimator.Estimate` (``amplitude`` = the RMS over channels of the
modal response summed in quadrature, ``fit`` = share of the summed channel variances the modes
explain) with its ``shape``, ``shape_std`` and ``mac`` with the mode's previous shape (NaN for a
mode's first window).

Bad samples never raise: a sample with any non-finite channel is skipped (``skipped_non_finite``);
stamps are handled as the single-channel identifier's (duplicates, out of order, gaps and jumps).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .ambient import SlidingWindowIdentifier
from .config import EstimatorConfig
from .estimator import Estimate, EstimateArrays, as_series

#: the fewest channels of a joint identification (one channel is the single-channel identifier's)
MIN_CHANNELS = 2


# ---- streaming ----------------------------------------------------------------------------------
@dataclass
class JointEstimates:
    """Estimates of a batch run: the columns of :class:`..estimator.EstimateArrays`, the shapes
    (estimates x channels, complex), their stds and the MACs, in the estimates' order."""

    estimates: EstimateArrays
    shapes: np.ndarray
    shape_std: np.ndarray
    mac: np.ndarray
    channels: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.estimates)

    @classmethod
    def of(cls, out: Sequence[Estimate], channels: tuple[str, ...]) -> 'JointEstimates':
        """The columns of the estimates ``out`` (with shapes) of ``channels``, in their order."""
        m = len(channels)
        return cls(
            EstimateArrays.of(out),
            np.array([e.shape for e in out], dtype=complex).reshape(-1, m),
            np.array([e.shape_std for e in out]).reshape(-1, m),
            np.array([e.mac for e in out]),
            channels,
        )


def channel_names(channels: Sequence[str], what: str, hint: str = '') -> tuple[str, ...]:
    """``channels`` as names; ValueError if they are fewer than :data:`MIN_CHANNELS` (``what``
    needs them; ``hint``: what to do instead)."""
    names = tuple(str(c) for c in channels)
    if len(names) < MIN_CHANNELS:
        raise ValueError(f'{what} needs at least {MIN_CHANNELS} channels, got {len(names)}{hint}')
    return names


def as_channels(t: Sequence[float], y: np.ndarray, channels: int) -> tuple[np.ndarray, np.ndarray]:
    """``t``, ``y`` as contiguous float64 arrays, ``y`` samples x ``channels`` (ValueError
    otherwise; the stamps' checks :func:`..estimator.as_series`'s)."""
    y = np.ascontiguousarray(y, dtype=np.float64)
    if y.ndim != 2 or y.shape[1] != channels:
        raise ValueError(f'y must be samples x {channels} channels, got {y.shape}')
    return as_series(t, y[:, 0])[0], y


class JointAmbientEstimator(SlidingWindowIdentifier):
    """Sliding-window joint output-only identification; see the module docstring.

    ``channels``: the channel names (their count is the number of columns fed)."""

    def __init__(self, config: EstimatorConfig, channels: Sequence[str]):
        hint = ' (one channel: excitation ambient, one column)'
        self.channels = channel_names(channels, 'a joint identification', hint)
        super().__init__(config, len(self.channels))

    def process(self, t: Sequence[float], y: np.ndarray) -> JointEstimates:
        """Feed arrays (``y``: samples x channels; continuing the stream); the estimates by
        time."""
        t, y = as_channels(t, y, len(self.channels))
        out = self._feed(t, y, np.isfinite(y).all(axis=1) & np.isfinite(t))
        return JointEstimates.of(out, self.channels)
