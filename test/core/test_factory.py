# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""One interface, one factory: every estimator of the table has the Estimator interface and one
counters vocabulary; the table alone decides which estimator a configuration gets (seeded)."""

import math

import numpy as np
import pytest

import vib_estimator
from vib_estimator.core import KINDS, Estimator, EstimatorConfig, create_estimator
from vib_estimator.core.estimator import INPUT_COUNTERS
from vib_estimator.core.factory import kind_of

FS = 200.0
NAMES = ('a', 'b', 'c')

#: a configuration of each row of the table, in its order
CONFIGS = {
    'algebraic': EstimatorConfig(),
    'mode tracker': EstimatorConfig(modes=2),
    'ambient': EstimatorConfig(excitation='ambient', ambient_window_s=4.0),
    'auto': EstimatorConfig(excitation='auto', ambient_window_s=4.0),
    'joint free': EstimatorConfig(),
    'joint ambient': EstimatorConfig(excitation='ambient', ambient_window_s=4.0),
}


def channels_of(kind) -> tuple:
    return NAMES if kind.joint else ()


def test_the_table_is_reached_from_the_public_api_in_one_hop():
    assert vib_estimator.create_estimator is create_estimator
    assert [k.name for k in vib_estimator.KINDS] == list(CONFIGS)


@pytest.mark.parametrize('kind', KINDS, ids=lambda k: k.name)
def test_each_row_is_the_estimator_of_its_configuration(kind):
    config = CONFIGS[kind.name]
    assert kind_of(config, len(channels_of(kind)) or 1) is kind
    est = create_estimator(config, channels_of(kind))
    assert type(est) is type(kind.build(config, channels_of(kind)))
    assert est.config == config and est.channels == channels_of(kind)
    assert Estimator in type(est).__mro__  # the interface's defaults: no getattr in the callers
    assert isinstance(est.mode_counters(), dict)
    assert est.segment_samples is None or est.segment_samples >= 0


def test_what_no_row_takes_is_refused_in_one_line():
    with pytest.raises(ValueError, match=r'^3 channels need excitation free or ambient .*auto'):
        create_estimator(EstimatorConfig(excitation='auto'), NAMES)
    with pytest.raises(ValueError, match=r'^2 topics need --excitation free or ambient'):
        kind_of(EstimatorConfig(excitation='auto'), 2, '2 topics', '--excitation')
    assert kind_of(EstimatorConfig(excitation='auto'), 1).name == 'auto'


def bad_samples(channels: int):
    """Samples of a noisy 7 Hz tone with a non-finite value, a duplicate and an out-of-order
    stamp every 50; their count."""
    rng = np.random.default_rng(3)
    t = np.arange(4000) / FS
    y = np.sin(2 * math.pi * 7.0 * t)[:, None] + 0.3 * rng.standard_normal((len(t), channels))
    t = t.copy()
    y[100::50, 0] = np.nan
    t[120::50] = t[119::50][: len(t[120::50])]
    t[140::50] = t[138::50][: len(t[140::50])]
    return t, y if channels > 1 else y[:, 0]


@pytest.mark.parametrize('kind', KINDS, ids=lambda k: k.name)
def test_one_interface_and_one_counters_vocabulary(kind):
    """``update`` returns a sequence, streaming equals batch, and the input counters add up:
    every sample received is used or skipped for a named reason."""
    names = channels_of(kind)
    t, y = bad_samples(len(names) or 1)
    batch = create_estimator(CONFIGS[kind.name], names)
    result = batch.process(t, y)
    stream = create_estimator(CONFIGS[kind.name], names)
    out = []
    for ti, yi in zip(t, y):
        got = stream.update(ti, yi)
        assert not isinstance(got, type(None))
        out.extend(got)
    assert len(out) == len(result)
    if not names:  # one channel: samples, or samples x 1 (a joint estimator's layout)
        again = create_estimator(CONFIGS[kind.name]).process(t, y[:, None])
        np.testing.assert_array_equal(again.frequency_hz, result.frequency_hz)
    c = batch.counters
    assert c == stream.counters
    assert list(c)[: len(INPUT_COUNTERS)] == list(INPUT_COUNTERS)
    skipped = sum(v for name, v in c.items() if name.startswith('skipped_'))
    assert c['received'] == len(t) == c['used'] + skipped
    assert min(c['skipped_non_finite'], c['skipped_duplicate'], c['skipped_out_of_order']) > 0
    assert c['estimates'] == len(result)
    batch.reset()
    batch.restart()
    assert batch.counters == c  # kept


def test_auto_keeps_the_identifiers_own_counters():
    """Under auto the identifier's counters that share a name with the free-decay estimator's
    are kept under ``ambient_`` (its ``rejected_damping`` was dropped)."""
    t = np.arange(20_000) / FS
    y = np.random.default_rng(5).standard_normal(len(t))
    est = create_estimator(CONFIGS['auto'])
    est.process(t, y)
    c = est.counters
    ambient = est._ambient.counters
    assert ambient['rejected_damping'] > 0
    assert c['ambient_rejected_damping'] == ambient['rejected_damping']
    assert c['ambient_estimates'] == ambient['estimates']


def test_the_batch_convenience_runs_the_configurations_estimator():
    """``core.estimate`` runs the estimator ``create_estimator`` builds (it ran the one-mode free
    estimator whatever ``modes`` said): a decay of 10 and 13 Hz with ``modes`` 3 gives both
    modes, numbered, the tracker's own batch's floats (its uncompiled start: within 1e-9)."""
    from vib_estimator.core import estimate

    t = np.arange(0, 6, 1e-3)
    y = np.exp(-0.02 * t) * np.sin(2 * np.pi * 10 * t) + 0.5 * np.sin(2 * np.pi * 13 * t + 1)
    y = y + 1e-3 * np.random.default_rng(0).standard_normal(len(t))
    config = EstimatorConfig(modes=3)
    e = estimate(t, y, config)
    assert set(e.mode.tolist()) == {1, 2}
    ref = create_estimator(config).process(t, y)
    assert np.allclose(e.frequency_hz, ref.frequency_hz, rtol=1e-9, atol=0)
