"""The estimator node's processing without ROS (nodes/stream.py): time base, estimator
replacement, counters, status (the reset service: test_estimator_node.py)."""
from __future__ import annotations

import numpy as np

from vib_estimator.core import EstimatorConfig, FrequencyEstimator
from vib_estimator.nodes import health as H
from vib_estimator.nodes.stream import EstimatorStream

EPOCH_NS = 1_700_000_000 * 10 ** 9


def sine(n, start=0, fs=500.0):
    stamps = EPOCH_NS + np.round(np.arange(start, start + n) * 1e9 / fs).astype(np.int64)
    return stamps, np.sin(2 * np.pi * 1.33 * np.arange(start, start + n) / fs)


def feed(stream, stamps, values):
    return [e for s, v in zip(stamps, values) for e in stream.feed(int(s), float(v))]


def test_same_floats_as_offline_with_epoch_stamps():
    stamps, values = sine(4000)     # 8 s: >= 5 windows of 1.25 periods (the default)
    stream = EstimatorStream(EstimatorConfig(), now=0.0)
    online = feed(stream, stamps, values)
    offline = FrequencyEstimator().process((stamps - stamps[0]) * 1e-9, values)
    assert len(online) >= 5 and [e.frequency_hz for e in online] == offline.frequency_hz.tolist()
    assert stream.last_t == (stamps[-1] - stamps[0]) * 1e-9


def test_configure_keeps_the_origin_and_the_counters():
    stamps, values = sine(3000)
    stream = EstimatorStream(EstimatorConfig(), now=0.0)
    feed(stream, stamps[:1000], values[:1000])
    stream.configure(EstimatorConfig(window=5))
    assert stream.config.window == 5
    later = feed(stream, stamps[1000:2000], values[1000:2000])
    expected = FrequencyEstimator(EstimatorConfig(window=5)).process(
        (stamps[1000:2000] - stamps[0]) * 1e-9, values[1000:2000])
    assert [e.frequency_hz for e in later] == expected.frequency_hz.tolist()
    assert stream.counters['received'] == 2000
    assert stream.counters['estimates'] == stream.health.totals({})['estimates'] + len(expected)


def test_status_knows_the_sampling_rate_and_the_last_estimate():
    stamps, values = sine(1001)
    stream = EstimatorStream(EstimatorConfig(band_hz=(10.0, 300.0)), now=0.0)
    for e in feed(stream, stamps, values):
        stream.published(e, now=0.5)
    status = stream.status(now=1.0)
    assert status.values['sample_rate_hz'] == 500.0
    assert status.level == H.WARN and 'Nyquist' in status.message      # 300 Hz > 250 Hz
    assert status.values['band_above_nyquist'] == 1001
    ok, message = stream.self_test()
    assert not ok and 'at 500 Hz sampling' in message
