# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The default of ``analyze``: with no ``--excitation`` (and no ``--paper``) the excitation and
the ambient window are decided from the record (:func:`..core.choice.decide`), and one line
(printed on stderr by the command once the record has been read without error) says what was
decided, from what, and which option overrides it."""

from __future__ import annotations

import itertools
from typing import Iterable, Iterator, Tuple

import numpy as np

from ..core.choice import DECIDE_S, decide
from ..core.config import EstimatorConfig


def decides(args) -> bool:
    """Whether the command line leaves the excitation to the record (no ``--excitation``, no
    ``--paper``)."""
    return getattr(args, 'excitation', None) is None and not getattr(args, 'paper', False)


def window_given(args) -> bool:
    """Whether the command line sets the ambient window (``--ambient-window-s``)."""
    return getattr(args, 'ambient_window_s', None) is not None


def decided_config(
    config: EstimatorConfig, t, y, channels: int, prog: str, keep_window: bool = False
) -> Tuple[EstimatorConfig, str]:
    """``config`` with the excitation and (unless ``keep_window``: ``--ambient-window-s`` was
    given) the ambient window that the record ``(t, y)`` needs, and the line that says so."""
    d = decide(t, y, channels, config.ambient_window_s)
    window = config.ambient_window_s
    if not keep_window and d.excitation != 'free':
        window = d.window_s
    line = (
        f'{prog}: excitation {d.excitation} (the default decides from the record: {d.reason}; '
        '--excitation free, ambient or auto overrides'
        + ('' if d.excitation == 'free' else ', --ambient-window-s the window')
        + ')'
    )
    return config.replace(excitation=d.excitation, ambient_window_s=window), line


def decided_blocks(
    config: EstimatorConfig,
    blocks: Iterable[Tuple[np.ndarray, np.ndarray]],
    prog: str,
    keep_window: bool = False,
) -> Tuple[EstimatorConfig, Iterator[Tuple[np.ndarray, np.ndarray]], str]:
    """For a streamed record: the blocks of its first :data:`..core.choice.DECIDE_S` s are read
    ahead and decided on (:func:`decided_config`); returns the configuration, every block (the
    ones read ahead first; memory: those seconds only) and the line that says what was decided."""
    blocks = iter(blocks)
    ahead, span = [], None
    for t, y in blocks:
        if not len(t):
            continue
        ahead.append((t, y))
        span = (float(ahead[0][0][0]), float(t[-1]))
        if span[1] - span[0] >= DECIDE_S:
            break
    line = ''
    if ahead:
        t = np.concatenate([b[0] for b in ahead])
        y = np.concatenate([b[1] for b in ahead])
        config, line = decided_config(config, t, y, 1, prog, keep_window)
    return config, itertools.chain(ahead, blocks), line
