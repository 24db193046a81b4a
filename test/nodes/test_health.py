# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The estimator node's diagnostics bookkeeping (nodes/health.py), self-test (nodes/self_test.py)
alone: no rclpy, no node, times given explicitly."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

from vib_estimator.core import COUNTER_NAMES, Estimate, EstimatorConfig
from vib_estimator.nodes import health as H
from vib_estimator.nodes.self_test import TOLERANCE, default_band, self_test, tone_frequencies


def core(**values):
    """Core counters, all zero but ``values``."""
    return {**dict.fromkeys(COUNTER_NAMES, 0), **values}


def estimate(f=1.33, mode=0, **kw):
    return Estimate(
        t=1.0,
        frequency_hz=f,
        convergence_time=0.4,
        samples=200,
        fit=0.99,
        amplitude=0.5,
        mode=mode,
        **kw,
    )


def test_health_and_self_test_import_no_rclpy():
    code = (
        'import sys, vib_estimator.nodes.health, vib_estimator.nodes.self_test; '
        'sys.exit(any(m.split(".")[0] == "rclpy" for m in sys.modules))'
    )
    assert subprocess.run([sys.executable, '-c', code]).returncode == 0


def test_counters_add_up_across_replaced_estimators():
    h = H.Health(now=0.0)
    h.absorb(core(received=10, used=9, estimates=2))
    h.absorb({'received': 5, 'finder_peaks': 3})  # a tracker's own counter
    assert h.count('zero_stamps_replaced') == 1
    assert h.count('skipped_joint_missing', 4) == 4
    totals = h.totals(core(received=7, used=7))
    assert totals['received'] == 22 and totals['used'] == 16 and totals['estimates'] == 2
    assert totals['finder_peaks'] == 3
    assert totals['zero_stamps_replaced'] == 1 and totals['skipped_joint_missing'] == 4
    assert totals['band_above_nyquist'] == 0
    assert list(totals)[-len(H.NODE_COUNTERS) :] == list(H.NODE_COUNTERS)


def test_the_sampling_rate_is_kept_over_a_gap_a_burst_or_stamps_going_back():
    """Samples used over the span of their stamps is the rate only where nothing was lost or
    went back: a 2-s stop (1000 samples missing) read 250 Hz for a 500 Hz input (the self-test
    then ran its tones at that rate, and a band's Nyquist check used it). Kept over the status
    whose counters grew and the one after (a gap is counted up to a status late), and across an
    estimator replaced (a new configuration); measured again after."""
    h = H.Health(now=0.0)
    h.status(1.0, h.totals(core(received=501, used=501)), 1.0)
    assert h.sample_rate_hz == 500
    h.count('samples_missing', 1000)
    h.status(2.0, h.totals(core(received=1001, used=1001)), 3.0)  # 500 samples over 2 s
    assert h.sample_rate_hz == 500
    h.status(3.0, h.totals(core(received=1301, used=1301)), 4.0)  # the status after: kept
    assert h.sample_rate_hz == 500
    h.status(4.0, h.totals(core(received=1701, used=1701)), 5.0)
    assert h.sample_rate_hz == 400  # measured again
    h.status(5.0, h.totals(core(received=2101, used=2101, skipped_out_of_order=3)), 6.0)
    assert h.sample_rate_hz == 400
    h.status(6.0, h.totals(core(received=2101, used=2101, skipped_out_of_order=3)), 7.0)
    h.status(7.0, h.totals(core(received=2501, used=2501, skipped_out_of_order=3)), 8.0)
    assert h.sample_rate_hz == 400
    h.absorb(core(received=10))  # an estimator replaced (a new configuration): kept across
    h.status(8.0, h.totals(core(received=2601, used=2601, skipped_out_of_order=3)), 9.0)
    assert h.sample_rate_hz == 400
    used, t = 2601, 9.0

    def status(n: int, span: float) -> float:
        """A status after ``n`` more samples used over ``span`` s of stamps."""
        nonlocal used, t
        used, t = used + n, t + span
        h.status(t, h.totals(core(received=used, used=used, skipped_out_of_order=3)), t)
        return h.sample_rate_hz

    assert [status(500, 1.0), status(500, 1.0)] == [400, 500]  # held after, measured again
    h.hold_rate()  # a gap in the stamps not yet counted (the node's cadence): kept
    assert [status(300, 2.0), status(500, 1.0), status(500, 1.0)] == [500, 500, 500]
    h.count('lost_in_transport', 200)  # the middleware's count of samples lost: kept
    assert [status(300, 2.0), status(500, 1.0), status(400, 1.0)] == [500, 500, 400]
    fresh = H.Health(now=0.0)  # none known yet: measured even so
    fresh.count('samples_missing', 10)
    fresh.status(1.0, fresh.totals(core(received=301, used=301)), 1.0)
    assert fresh.sample_rate_hz == 300


def test_stale_ok_warn_and_the_rates():
    h = H.Health(now=0.0)
    s = h.status(1.0, h.totals(core()), None)
    assert (s.level, s.message) == (H.STALE, 'no input')
    assert math.isnan(s.values['last_frequency_hz']) and math.isnan(s.values['sample_rate_hz'])
    # 501 samples stamped 0..1 s arrive within the second 1..2
    s = h.status(2.0, h.totals(core(received=501, used=501)), 1.0)
    assert (s.level, s.message) == (H.OK, 'waiting for a first estimate')
    assert s.values['input_rate_hz'] == 501 and s.values['sample_rate_hz'] == 500
    h.record(estimate(frequency_std_hz=1e-3), 2.5, h.totals(core(received=600, used=600)))
    s = h.status(3.0, h.totals(core(received=1001, used=1001, estimates=1)), 2.0)
    assert (s.level, s.message) == (H.OK, 'estimating')
    assert s.values['sample_rate_hz'] == 500 and s.values['input_rate_hz'] == 500
    assert s.values['last_frequency_hz'] == 1.33 and s.values['last_estimate_age_s'] == 0.5
    assert s.values['last_frequency_std_hz'] == 1e-3 and math.isnan(s.values['last_damping_std'])
    assert s.values['last_amplitude'] == 0.5 and s.values['estimates'] == 1
    # the gate holds a segment back: WARN until the next estimate
    held = core(received=1501, used=1501, estimates=1, rejected_fit=1)
    s = h.status(4.0, h.totals(held), 3.0)
    assert s.level == H.WARN and s.message == (
        'held back since the last estimate: rejected_fit 1 (the model fits the segment under '
        'min_fit)'
    )
    h.record(estimate(), 4.2, h.totals(held))
    assert h.status(5.0, h.totals({**held, 'received': 2000}), 4.0).level == H.OK
    # no input for more than STALE_AFTER
    assert (
        h.status(5.0 + H.STALE_AFTER + 0.1, h.totals({**held, 'received': 2000}), 4.0).level
        == H.STALE
    )


def test_missing_joints_warn():
    h = H.Health(now=0.0)
    h.count('skipped_joint_missing', 30)
    s = h.status(1.0, h.totals(core()), None)  # only skipped messages: input, but WARN
    assert s.level == H.WARN and '30 messages without the joint' in s.message
    assert s.values['input_rate_hz'] == 30
    assert h.status(2.0, h.totals(core(received=10)), 0.1).level == H.OK


def test_band_above_nyquist_warns_once_and_counts():
    h = H.Health(now=0.0)
    s = h.status(1.0, h.totals(core(received=101, used=101)), 1.0, band_hz=(10.0, 60.0))
    assert s.level == H.WARN and 'Nyquist frequency 50 Hz' in s.message
    assert s.log is not None and 'band_hz upper edge 60 Hz' in s.log
    assert s.values['band_above_nyquist'] == 101
    s = h.status(2.0, h.totals(core(received=201, used=201)), 2.0, band_hz=(10.0, 60.0))
    assert s.log is None and s.values['band_above_nyquist'] == 201  # logged once
    s = h.status(3.0, h.totals(core(received=301, used=301)), 3.0, band_hz=(10.0, 40.0))
    assert s.level == H.OK and s.log is None and s.values['band_above_nyquist'] == 201
    s = h.status(4.0, h.totals(core(received=401, used=401)), 4.0, band_hz=(10.0, 50.0))
    assert s.level == H.WARN and s.log is not None  # a new band: logged


def test_modes_have_their_last_frequency_and_age():
    h = H.Health(now=0.0)
    totals = h.totals(core(received=10, used=10))
    h.record(estimate(1.3, mode=1), 1.0, totals)
    h.record(estimate(8.2, mode=2, frequency_std_hz=0.01), 1.5, totals)
    s = h.status(2.0, totals, 0.1, modes=3)
    v = s.values
    assert v['mode1_frequency_hz'] == 1.3 and v['mode1_age_s'] == 1.0
    assert v['mode2_frequency_hz'] == 8.2 and v['mode2_age_s'] == 0.5
    assert v['mode2_frequency_std_hz'] == 0.01
    assert math.isnan(v['mode3_frequency_hz']) and math.isnan(v['mode3_age_s'])
    assert v['last_frequency_hz'] == 1.3  # vibration/frequency carries mode 1
    h.forget_modes(1)
    assert 'mode2_frequency_hz' not in h.status(3.0, totals, 0.1, modes=1).values
    assert not any(k.startswith('mode') for k in h.status(3.0, totals, 0.1).values)


def test_format_value():
    assert H.format_value(3) == '3' and H.format_value(1 / 3) == '0.333333333'
    assert H.format_value(math.nan) == 'nan'


@pytest.mark.parametrize(
    'model, modes',
    [('sinusoid', 0), ('biased-sinusoid', 0), ('damped-sinusoid', 0), ('sinusoid', 1)],
)
def test_self_test_passes_with_the_defaults(model, modes):
    ok, message = self_test(EstimatorConfig(model=model, modes=modes))
    lines = message.splitlines()
    assert ok and lines[0].startswith('passed') and len(lines) == 4, message
    assert all('error' in line for line in lines[1:])


@pytest.mark.parametrize('excitation', ['ambient', 'auto'])
def test_self_test_passes_under_the_identifier(excitation):
    """``excitation`` ambient (what the node's default decides for a driven input) or auto:
    each tone a white-noise-driven mode over three windows (a pure sine of ten periods gave
    "no estimate" on every tone)."""
    ok, message = self_test(EstimatorConfig(excitation=excitation), 500.0)
    lines = message.splitlines()
    assert ok and len(lines) == 4 and all('error' in line for line in lines[1:]), message


def test_self_test_tones_span_the_band():
    assert tone_frequencies((1.0, 16.0), 500.0) == pytest.approx([2.0, 4.0, 8.0])
    lo, hi = default_band(500.0)
    assert all(lo < f < hi for f in tone_frequencies(None, 500.0))
    ok, message = self_test(EstimatorConfig(band_hz=(0.5, 2.0)), 200.0)
    assert ok, message
    for f, line in zip(tone_frequencies((0.5, 2.0), 200.0), message.splitlines()[1:]):
        assert line.startswith(f'{f:.4g} Hz: median')
        error = float(line.split('error ')[1].split(' %')[0])
        assert abs(error) <= 100 * TOLERANCE


def test_self_test_fails_with_a_reason():
    ok, message = self_test(EstimatorConfig(band_hz=(100.0, 400.0)), 500.0)
    assert not ok and message.startswith('FAILED')
    assert 'above the Nyquist frequency 250 Hz' in message.splitlines()[-1]
    ok, message = self_test(EstimatorConfig(min_amplitude=1e6, min_fit=0.0), 500.0)
    assert ok  # the tones' amplitude follows the at-rest gate


def test_an_estimate_of_any_mode_clears_held_back():
    h = H.Health(now=0.0)
    held = h.totals(core(received=100, used=100, rejected_fit=2))
    assert h.status(1.0, held, 0.2, modes=2).level == H.WARN
    h.record(estimate(8.0, mode=2), 1.5, held)
    s = h.status(2.0, h.totals(core(received=200, used=200, rejected_fit=2)), 0.4, modes=2)
    assert s.level == H.OK and s.message == 'waiting for a first estimate'  # of mode 1


def test_gaps_and_outliers_warn_and_are_logged_once_per_episode():
    """Issue 22 case 1/2 in the diagnostics: gaps and skipped outliers since the last status make
    it WARN, saying how many samples were lost; the warning is logged when the episode starts."""
    h = H.Health(now=0.0)
    h.record(estimate(), 0.5, h.totals(core()))
    s = h.status(1.0, h.totals(core(received=500, used=500)), 1.0)
    assert s.level == H.OK and s.log is None
    s = h.status(
        2.0,
        h.totals(core(received=900, used=899, gaps=2, samples_lost=100, skipped_outlier=1)),
        2.0,
    )
    assert s.level == H.WARN and '2 gaps (100 samples lost' in s.message
    assert '1 outliers skipped' in s.message and s.log is not None
    s = h.status(
        3.0,
        h.totals(core(received=1300, used=1298, gaps=3, samples_lost=150, skipped_outlier=2)),
        3.0,
    )
    assert s.level == H.WARN and '1 gaps (50 samples lost' in s.message and s.log is None
    s = h.status(
        4.0,
        h.totals(core(received=1800, used=1798, gaps=3, samples_lost=150, skipped_outlier=2)),
        4.0,
    )
    assert s.level == H.OK and s.values['gaps'] == 3 and s.values['samples_lost'] == 150


def test_alignment_status_names_a_lagging_topic_and_new_drops():
    """Several input topics: the status carries what waits and which topic lags; it turns WARN
    for a lagging topic or for drops since the previous status, and keeps STALE (with the
    reason) when nothing came through."""
    ok = H.Status(H.OK, 'estimating', {'received': 10})
    counters = {'dropped_unaligned': 0, 'dropped_stalled': 0}
    calm = H.alignment_status(ok, [], 0, counters, counters)
    assert calm.level == H.OK and calm.message == 'estimating'
    assert calm.values == {'received': 10, 'pending_aligned': 0, 'lagging_topics': ''}
    lag = H.alignment_status(ok, ['/joint3/torque'], 2000, counters, counters)
    assert lag.level == H.WARN and lag.message.startswith('/joint3/torque behind')
    assert (
        lag.values['lagging_topics'] == '/joint3/torque' and lag.values['pending_aligned'] == 2000
    )
    grown = {'dropped_unaligned': 7, 'dropped_stalled': 3}
    drops = H.alignment_status(ok, [], 0, grown, counters)
    assert drops.level == H.WARN
    assert '7 samples without a partner' in drops.message and '3 samples dropped' in drops.message
    assert H.alignment_status(ok, [], 0, grown, grown).level == H.OK  # nothing new
    stale = H.alignment_status(H.Status(H.STALE, 'no input', {}), ['/b'], 5, counters, counters)
    assert stale.level == H.STALE and stale.message.startswith('no input; /b behind')


def test_the_identities_fail_when_a_sample_is_unaccounted():
    c = {'received': 10, 'used': 8, 'skipped_duplicate': 1, 'skipped_outlier': 1}
    c.update(samples_missing=5, lost_in_queue=2, missing_in_gaps=3)
    assert all(H.identities(c).values())
    assert not all(H.identities({**c, 'used': 7}).values())
    assert not all(H.identities({**c, 'missing_in_gaps': 2}).values())


def test_each_held_back_counter_is_explained_with_a_parameter_of_the_node():
    """The WARN of a held-back estimate says why in words and names the parameter that changes
    it: each a parameter of ``estimator_node`` (config/estimator.yaml, the parameters' one
    source), so the advice can be followed as written."""
    import pathlib
    import re

    import yaml

    config = pathlib.Path(__file__).resolve().parents[2] / 'config' / 'estimator.yaml'
    params = set(yaml.safe_load(config.read_text())['/**']['ros__parameters'])
    assert set(H.WHY_HELD) == set(H.HELD_BACK)
    for name, why in H.WHY_HELD.items():
        assert set(re.findall(r'\b[a-z_]+\b', why)) & params, (name, why)  # names one
        assert set(re.findall(r'\b([a-z_]+):=', why)) <= params, (name, why)  # sets real ones
