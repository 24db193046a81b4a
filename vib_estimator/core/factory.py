# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The estimator of a configuration: one table of the estimators, one factory, each rule once.

:func:`create_estimator` ``(config, channels=())`` is how every caller (the estimator node's
stream, ``analyze``, ``survey``, the self-test, the warm-up, the demos) gets an estimator; each
implements :class:`~.estimator.Estimator`. Which one is read from :data:`KINDS`, a row per
estimator: the ``excitation`` it serves, whether it takes one channel or several (``joint``) and,
where one excitation has two, which ``modes`` it takes. A configuration and a channel count that
match no row are refused by :func:`kind_of`, with one line that says which excitations would take
them (the rule "several channels need free or ambient" is the table's, written nowhere else).

Adding an estimator: its module (a class with the :class:`~.estimator.Estimator` interface) and
its row here.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import Callable, Optional, Sequence

from .ambient import AmbientEstimator
from .auto import AutoEstimator
from .config import EstimatorConfig
from .estimator import (
    MIN_CHANNELS,
    EstimateArrays,
    Estimator,
    FrequencyEstimator,
    batch_start,
    run_batch,
)
from .modes import ModeTracker
from .multichannel_free import JointFreeEstimator


@dataclass(frozen=True)
class Kind:
    """A row of :data:`KINDS`: ``build(config, channels)`` makes the estimator of ``excitation``
    for one channel or (``joint``) several; ``tracks`` True: only with ``modes`` >= 1, False:
    only with ``modes`` = 0, None: any; ``numbered``: its estimates carry a mode number;
    ``uncompiled(config)``: the same estimator with its kernels uncompiled (estimating at once
    while they compile: :func:`create_uncompiled`), None where it has none to run so."""

    name: str
    excitation: str
    joint: bool
    build: Callable[[EstimatorConfig, tuple], Estimator]
    tracks: Optional[bool] = None
    numbered: bool = True
    uncompiled: Optional[Callable[[EstimatorConfig], Estimator]] = None

    def takes(self, config: EstimatorConfig, joint: bool) -> bool:
        """Whether this row is the estimator of ``config`` for one channel or several."""
        modes = self.tracks is None or self.tracks == (config.modes > 0)
        return self.excitation == config.excitation and self.joint == joint and modes


#: the estimators, a row each (module doc)
KINDS = (
    Kind(
        'algebraic',
        'free',
        False,
        lambda c, _: FrequencyEstimator(c),
        False,
        False,
        partial(FrequencyEstimator, interpret=True),
    ),
    Kind(
        'mode tracker',
        'free',
        False,
        lambda c, _: ModeTracker(c),
        tracks=True,
        uncompiled=partial(ModeTracker, interpret=True),
    ),
    Kind('ambient', 'ambient', False, lambda c, _: AmbientEstimator(c)),
    Kind(
        'auto',
        'auto',
        False,
        lambda c, _: AutoEstimator(c, create_estimator(c.replace(excitation='free'))),
    ),
    Kind(
        'joint free',
        'free',
        True,
        lambda c, names: JointFreeEstimator(
            c,
            names,
            partial(ModeTracker, c, fast=False) if c.modes else partial(create_estimator, c),
        ),
    ),
    Kind('joint ambient', 'ambient', True, AmbientEstimator),
)


def kind_of(
    config: EstimatorConfig, channels: int = 1, what: str = '', option: str = 'excitation'
) -> Kind:
    """The row of :data:`KINDS` for ``config`` and ``channels`` (a count); else ValueError:
    ``what`` (default: N channels) need ``option`` (the caller's spelling of ``excitation``)
    one of the excitations that take that many."""
    joint = channels >= MIN_CHANNELS
    for kind in KINDS:
        if kind.takes(config, joint):
            return kind
    allowed = ' or '.join(dict.fromkeys(k.excitation for k in KINDS if k.joint == joint))
    what = what or f'{channels} channels'
    raise ValueError(
        f'{what} need {option} {allowed} (a joint estimation), got {option} '
        f'{config.excitation}: it takes one channel'
        if joint
        else f'one channel needs {option} {allowed}, got {config.excitation}'
    )


def create_estimator(config: EstimatorConfig, channels: Sequence[str] = ()) -> Estimator:
    """The estimator of ``config`` for the named ``channels`` (none or one: a one-channel
    estimator, fed one value a sample; several: a joint one, fed a row of values): the row of
    :data:`KINDS` that takes them (:func:`kind_of`; ValueError if none)."""
    channels = tuple(str(c) for c in channels)
    return kind_of(config, max(len(channels), 1)).build(config, channels)


def create_uncompiled(
    config: EstimatorConfig, channels: Sequence[str] = ()
) -> Optional[Estimator]:
    """The estimator of :func:`create_estimator` with its kernels uncompiled (its row's
    ``uncompiled``: the one-channel free-decay estimators, with or without ``band_hz`` and
    ``modes``), built without compiling anything; None for the others. Its ``compiled()``
    switches it to its compiled kernels between two samples."""
    kind = kind_of(config, max(len(channels), 1))
    return None if kind.uncompiled is None else kind.uncompiled(config)


def batch_estimator(config: EstimatorConfig, channels: Sequence[str] = ()) -> Estimator:
    """The estimator of :func:`create_estimator` for a batch run (``analyze``): uncompiled at
    first when its compiled kernels would have to be compiled for it (:func:`create_uncompiled`,
    :func:`~.estimator.batch_start`; feed it with :func:`~.estimator.run_batch`)."""
    estimator = create_uncompiled(config, channels)
    if estimator is None:
        return create_estimator(config, channels)
    batch_start(estimator)
    return estimator


def estimate(
    t: Sequence[float], y: Sequence[float], config: EstimatorConfig = EstimatorConfig()
) -> EstimateArrays:
    """Batch convenience: the estimates of ``config``'s estimator (:func:`create_estimator`, one
    channel) over a whole record, run as ``analyze`` runs it (:func:`batch_estimator`,
    :func:`~.estimator.run_batch`: uncompiled at first when its kernels would have to be compiled
    for it). (Until 6 Dec 2026 it ran the one-mode free estimator whatever ``modes`` and
    ``excitation`` said.)"""
    return run_batch(batch_estimator(config), t, y)
