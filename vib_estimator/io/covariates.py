# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Covariates of a recording (temperature, load, ...): the mean of a numeric field of a bag topic
(``TOPIC:FIELD``, any message type, ``FIELD`` a dotted attribute path such as ``temperature`` of
``sensor_msgs/msg/Temperature`` or ``data`` of ``std_msgs/msg/Float64``) or of a CSV column
(``NAME``; a ``TOPIC:NAME`` spec reads the column ``NAME``). Raises BagError, CsvError or
ValueError naming what is missing."""

from __future__ import annotations

import math
from operator import attrgetter
from pathlib import Path
from typing import List, Sequence, Tuple

import numpy as np

from .bags import TYPESTORE, BagReader
from .csv_reader import read_csv_series
from .streaming import is_csv

Spec = Tuple[str, str]


def parse_covariates(text: str) -> List[str]:
    """``--covariates`` / ``covariate_topics``: comma-separated specs, each ``TOPIC:FIELD`` or a
    CSV column name; ValueError if empty or malformed."""
    specs = [s.strip() for s in text.split(',') if s.strip()]
    if not specs:
        raise ValueError(f'--covariates: no covariate in {text!r}')
    for spec in specs:
        topic, _, name = spec.rpartition(':')
        if not name or (spec.count(':') and not topic):
            raise ValueError(f'--covariates: {spec!r} is neither TOPIC:FIELD nor a column name')
    if len(set(specs)) != len(specs):
        raise ValueError(f'--covariates: a covariate given twice in {text!r}')
    return specs


def split_spec(spec: str) -> Spec:
    """``(topic, field)`` of a spec (topic '' for a bare CSV column name)."""
    topic, _, name = spec.rpartition(':')
    return topic, name


def field_getter(name: str):
    """A getter of the numeric field ``name`` (dotted path) of a message."""
    return attrgetter(name)


def covariate_means(path, specs: Sequence[str]) -> List[float]:
    """Each covariate's mean over the recording ``path`` (NaN values ignored); ValueError if a
    topic, field or column is missing or holds no finite value."""
    path = Path(path)
    if is_csv(path):
        return [_csv_mean(path, split_spec(s)[1]) for s in specs]
    specs = [split_spec(s) for s in specs]
    if any(not topic for topic, _ in specs):
        raise ValueError(f'{path}: a bag covariate is TOPIC:FIELD')
    sums = {s: [0.0, 0] for s in specs}
    with BagReader(path) as bag:
        topics = sorted({t for t, _ in specs})
        kinds = {t: bag.topic(t).msgtype for t in topics}
        getters = {s: field_getter(s[1]) for s in specs}
        for message in bag.messages(topics):
            msg = TYPESTORE.deserialize_cdr(message.data, kinds[message.topic])
            for spec in specs:
                if spec[0] != message.topic:
                    continue
                try:
                    value = float(getters[spec](msg))
                except (AttributeError, TypeError, ValueError):
                    raise ValueError(
                        f'{path}: topic {spec[0]} ({kinds[spec[0]]}) has no numeric field '
                        f'{spec[1]!r}'
                    ) from None
                if math.isfinite(value):
                    sums[spec][0] += value
                    sums[spec][1] += 1
    out = []
    for spec in specs:
        total, count = sums[spec]
        if not count:
            raise ValueError(f'{path}: covariate {spec[0]}:{spec[1]} has no finite value')
        out.append(total / count)
    return out


def _csv_mean(path: Path, column: str) -> float:
    values = read_csv_series(path, column).y
    values = values[np.isfinite(values)]
    if not values.size:
        raise ValueError(f'{path}: covariate column {column!r} has no finite value')
    return float(values.mean())
