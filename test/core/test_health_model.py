# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The learned health baseline's mathematics against seeded simulations of known false-alarm rate,
its mode matching, its CUSUM and its YAML file."""

import math

import numpy as np
import pytest

from vib_estimator.core import health_model as hm


def _fleet(rng, n, slope=-0.016, f0=8.0, s=0.004, x=None):
    x = rng.uniform(-10, 0, n) if x is None else x
    return f0 + slope * x + s * rng.standard_normal(n), x


def test_fit_recovers_the_regression():
    rng = np.random.default_rng(0)
    f, x = _fleet(rng, 400)
    m = hm.fit_mode('/a', 'z', 1, f, x)
    assert m.dof == 398 and m.n == 400
    assert m.residual_std_hz == pytest.approx(0.004, rel=0.1)
    assert m.predict([5.0])[0] == pytest.approx(8.0 - 0.016 * 5, abs=0.002)
    assert m.x_range[0][0] >= -10 and m.x_range[0][1] <= 0


def test_false_alarm_rate_is_the_stated_one_even_when_extrapolating():
    """A new recording far outside a short training range (leverage ~1.5): the test must keep
    its false-alarm probability P; without the parameters' uncertainty it would be ~3x P."""
    rng = np.random.default_rng(1)
    p, trials, alarms = 0.02, 6000, 0
    x_train = np.linspace(-10, 0, 8)
    for _ in range(trials):
        f, _ = _fleet(rng, 8, x=x_train)
        mode = hm.fit_mode('/a', 'z', 1, f, x_train)
        base = hm.Baseline(['t'], [mode], p)
        new, _ = _fleet(rng, 1, x=np.array([8.0]))
        alarms += base.change(mode, float(new[0]), [8.0]).alarm
    rate = alarms / trials
    # binomial std of the rate: sqrt(p (1-p) / trials) = 0.0018; 5 sigma
    assert abs(rate - p) < 0.009, rate


def test_change_interval_covers_at_95_percent():
    rng = np.random.default_rng(2)
    covered, trials = 0, 2000
    for _ in range(trials):
        f, x = _fleet(rng, 30)
        mode = hm.fit_mode('/a', 'z', 1, f, x)
        base = hm.Baseline(['t'], [mode])
        shift = 0.005
        new, _ = _fleet(rng, 1, x=np.array([-3.0]))
        c = base.change(mode, float(new[0]) * (1 + shift), [-3.0])
        covered += c.change_lo <= shift <= c.change_hi
    assert abs(covered / trials - 0.95) < 0.025


def test_detects_a_shift_beyond_its_limit():
    rng = np.random.default_rng(3)
    f, x = _fleet(rng, 80)
    base = hm.Baseline(['t'], [hm.fit_mode('/a', 'z', 1, f, x)])
    mode = base.modes[0]
    f_hat = mode.predict([-5.0])[0]
    limit = base.change(mode, f_hat, [-5.0]).limit_rel
    # t(78) at 1 - 0.0005 is 3.41: the limit is that many prediction stds
    assert limit == pytest.approx(3.41 * mode.predict([-5.0])[1] / f_hat, rel=0.01)
    assert base.change(mode, f_hat * (1 - 1.05 * limit), [-5.0]).alarm
    assert not base.change(mode, f_hat * (1 - 0.95 * limit), [-5.0]).alarm


def test_too_few_or_constant_covariates_are_refused():
    with pytest.raises(ValueError, match='need at least 4'):
        hm.fit_mode('/a', 'z', 1, [1.0, 1.1, 1.2], [[0.0], [1.0], [2.0]])
    with pytest.raises(ValueError, match='does not vary'):
        hm.fit_mode('/a', 'z', 1, [1.0, 1.1, 1.2, 1.3], [[2.0]] * 4)


def _rows(rng, n=40):
    rows = []
    for i in range(n):
        x = rng.uniform(-10, 10)
        for mode, f0 in ((1, 8.0), (2, 21.0)):
            rows.append(
                dict(
                    recording=f'day{i:03d}',
                    topic='/accel',
                    component='z',
                    mode=mode,
                    frequency_hz=f0 * (1 - 0.002 * x + 0.0005 * rng.standard_normal()),
                    x=x,
                )
            )
        if i % 9 == 0:  # a spurious mode now and then, numbered between the two
            rows.append(
                dict(
                    recording=f'day{i:03d}',
                    topic='/accel',
                    component='z',
                    mode=2,
                    frequency_hz=13.0,
                    x=x,
                )
            )
    return rows


def test_learn_groups_modes_by_frequency_and_ignores_rare_ones():
    rows = _rows(np.random.default_rng(4))
    base = hm.learn(rows, ['x'], lambda r: [r['x']])
    assert [m.mode for m in base.modes] == [1, 2]
    assert [round(m.frequency_hz) for m in base.modes] == [8, 21]
    assert base.modes[0].coef[1] == pytest.approx(-0.016, rel=0.05)


def test_match_by_frequency_pinned_from_both_sides():
    base = hm.learn(_rows(np.random.default_rng(5)), ['x'], lambda r: [r['x']])
    # a 1 % damage is still mode 1 (MATCH_REL at 0.001x would lose it)
    assert base.match('/accel', 'z', 8.0 * 0.99, [0.0]).mode == 1
    # 13 Hz is no mode (MATCH_REL or MATCH_FAR at 1000x would call it mode 1 or 2)
    assert base.match('/accel', 'z', 13.0, [0.0]) is None
    assert base.match('/other', 'z', 8.0, [0.0]) is None
    # a 15 % change is still its mode (MATCH_FAR at 0.001x would lose it); 25 %: too far
    assert base.match('/accel', 'z', 8.0 * 0.85, [0.0]).mode == 1
    assert base.match('/accel', 'z', 21.0 * 1.15, [0.0]).mode == 2
    assert base.match('/accel', 'z', 21.0 * 1.25, [0.0]) is None


def test_match_by_shape():
    rng = np.random.default_rng(6)
    f, x = _fleet(rng, 20)
    mode = hm.fit_mode('/a', 'x,y', 1, f, x, shape=[1.0, 0.0])
    base = hm.Baseline(['t'], [mode])
    assert base.match('/a', 'x,y', 8.0, [-5.0], np.array([0.9, 0.1])) is mode
    assert base.match('/a', 'x,y', 8.0, [-5.0], np.array([0.0, 1.0])) is None
    # MAC 0.5: another mode at the same frequency (MATCH_MAC at 0.001x would take it)
    assert base.match('/a', 'x,y', 8.0, [-5.0], np.array([1.0, 1.0])) is None


def test_cusum_threshold_from_the_false_alarm_probability():
    """h is set so that the two-sided in-control run length is 1/P: measured on 300 seeded runs
    at P = 0.01 (~100 recordings); a shift of 2 std is found within ~4."""
    h = hm.cusum_threshold(0.001)
    assert h == pytest.approx(5.75, abs=0.01)
    assert hm.cusum_arl(h) == pytest.approx(2000, rel=1e-6)
    assert hm.cusum_arl(h, 2.0) == pytest.approx(4.4, rel=0.05)
    rng = np.random.default_rng(7)
    h = hm.cusum_threshold(0.01)
    runs = []
    for _ in range(300):
        c, n = hm.Cusum(h), 0
        while not c.update(float(rng.standard_normal())):
            n += 1
        runs.append(n + 1)
    # Siegmund's approximation is within ~10 % here; the mean of 300 runs within ~6 %
    assert 75 < np.mean(runs) < 130, np.mean(runs)
    c = hm.Cusum(hm.cusum_threshold(0.001))
    for n in range(1, 40):
        if c.update(float(rng.standard_normal()) - 2.0):
            break
    assert n <= 10 and c.value < 0


def _cusum_run(mode, truth, x, n, shared=True, seed=10):
    """Recordings at covariate ``x`` of true frequency ``truth`` (noise 0.004 Hz): the first
    one the CUSUM alarms on (None if none of ``n``)."""
    rng = np.random.default_rng(seed)
    base = hm.Baseline(['t'], [mode])
    c = hm.Cusum(base.cusum_h())
    for i in range(n):
        change = base.change(mode, truth + 0.004 * rng.standard_normal(), [x])
        if c.update(change.z, change.shared if shared else 0.0):
            return i
    return None


def test_cusum_does_not_accumulate_the_regressions_own_error():
    """An unlucky training (its slope 2 of its stds off) extrapolated to +10 degC: the prediction
    errs by ~1.4 se on every later recording. The per-recording test allows for it; the CUSUM
    must too (CUSUM_SHARED at 0.001x alarms within ~10 recordings), yet find a shift of 2 se
    inside the training range (at 1000x it would never)."""
    rng = np.random.default_rng(9)
    x = np.linspace(-10, 0, 30)
    tilt = 2 * 0.004 / np.sqrt(np.sum((x - x.mean()) ** 2))  # 2 stds of the slope
    f = 8 - 0.016 * x + tilt * (x - x.mean()) + 0.004 * rng.standard_normal(30)
    mode = hm.fit_mode('/a', 'z', 1, f, x)
    assert _cusum_run(mode, 8 - 0.016 * 10, 10.0, 60) is None
    assert _cusum_run(mode, 8 - 0.016 * 10, 10.0, 60, shared=False) is not None
    inside = 8 - 0.016 * -5 - 2 * mode.predict([-5.0])[1]
    assert _cusum_run(mode, inside, -5.0, 60) < 10


def test_save_load_round_trip(tmp_path):
    base = hm.learn(
        _rows(np.random.default_rng(8)),
        ['/temperature:temperature'],
        lambda r: [r['x']],
        false_alarm=0.01,
        trained_on='40 recordings',
    )
    hm.save(base, tmp_path / 'b.yaml')
    text = (tmp_path / 'b.yaml').read_text()
    assert text.startswith('version: 1\n')
    again = hm.load(tmp_path / 'b.yaml')
    assert again.to_dict() == base.to_dict()
    m, m2 = base.modes[1], again.modes[1]
    assert m2.predict([3.0]) == m.predict([3.0])
    assert again.change(m2, 20.5, [3.0]) == base.change(m, 20.5, [3.0])


def test_load_refuses_other_files(tmp_path):
    bad = tmp_path / 'b.yaml'
    bad.write_text('version: 2\nmodes: []\n')
    with pytest.raises(ValueError, match='version 2'):
        hm.load(bad)
    bad.write_text('a: [1\n')
    with pytest.raises(ValueError, match='cannot read'):
        hm.load(bad)
    bad.write_text('version: 1\ncovariates: [a]\nmodes: [{topic: x}]\n')
    with pytest.raises(ValueError, match='bad or missing field'):
        hm.load(bad)


def test_threshold_is_student_t():
    mode = hm.fit_mode(
        '/a', 'z', 1, [1.0, 1.1, 1.05, 1.2, 0.9], [[0.0], [1.0], [2.0], [3.0], [4.0]]
    )
    base = hm.Baseline(['t'], [mode], 0.001)
    assert base.threshold(mode) == pytest.approx(12.92, rel=0.01)  # t(3) at 0.9995
    assert math.isfinite(base.change(mode, 1.0, [9.0]).limit_rel)
