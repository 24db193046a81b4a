# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Several channels, one set of modes: joint SSI-cov with mode shapes (seeded, tolerant)."""

import math

import numpy as np
import pytest

from vib_estimator.core import EstimatorConfig
from vib_estimator.core.ambient import AmbientEstimator
from vib_estimator.core.shapes import mac
from vib_estimator.sim.arm_model import simulate_driven
from vib_estimator.sim.frame import frame_record, modal_record, shear_frame

from .test_ambient_incremental import correlation_matrices

#: 6 Hz at 0.3 of the rate: the frame's modes without decimation (a short test)
FS = 20.0
CONFIG = EstimatorConfig(excitation='ambient', ambient_window_s=60.0)


def _per_mode(result, freqs, shapes):
    """For each true mode: (median relative error, median damping, median MAC) of the
    estimates nearest to it."""
    e = result.estimates
    near = np.argmin(np.abs(e.frequency_hz[:, None] / freqs[None, :] - 1), axis=1)
    out = []
    for j, f in enumerate(freqs):
        m = near == j
        if not np.any(m):
            out.append((math.inf, math.nan, 0.0))
            continue
        macs = [mac(s, shapes[:, j]) for s in result.shapes[m]]
        out.append(
            (
                abs(np.median(e.frequency_hz[m]) / f - 1),
                float(np.median(e.damping[m])),
                float(np.median(macs)),
            )
        )
    return out


def test_shear_frame_modes():
    freqs, _ = shear_frame()
    assert freqs[0] == pytest.approx(0.89) and 5.9 < freqs[-1] < 6.1


@pytest.mark.parametrize('seed', [1, 2])
def test_five_storey_frame_five_modes_with_shapes(seed):
    t, y, freqs, shapes = frame_record(600.0, FS, zeta=0.02, snr_db=20.0, seed=seed)
    result = AmbientEstimator(CONFIG, [f'storey{i}' for i in range(1, 6)]).process(t, y)
    assert len(result) > 100
    for err, zeta, similarity in _per_mode(result, freqs, shapes):
        assert err <= 0.01
        assert 0.65 * 0.02 <= zeta <= 1.5 * 0.02
        assert similarity >= 0.95
    # the shapes: normalised, their stds finite, the MAC between consecutive windows near 1
    assert np.allclose(np.linalg.norm(result.shapes, axis=1), 1.0)
    assert np.all(np.isfinite(result.shape_std))
    assert np.nanmedian(result.mac) > 0.95


def test_a_mode_invisible_on_some_channels_is_found():
    modes = [(1.0, 0.02, 1.0), (2.5, 0.02, 0.3), (4.0, 0.02, 1.0)]
    shapes = np.array([[1.0, 0.0, 0.6], [0.8, 0.0, -0.7], [0.5, 1.0, 0.9]])
    t, y = modal_record(400.0, FS, modes, shapes, snr_db=20.0, seed=3)
    result = AmbientEstimator(CONFIG, ['a', 'b', 'c']).process(t, y)
    freqs = np.array([f for f, _, _ in modes])
    per = _per_mode(result, freqs, shapes / np.linalg.norm(shapes, axis=0))
    for err, _, similarity in per:
        assert err <= 0.01 and similarity >= 0.95
    e = result.estimates
    hidden = np.abs(e.frequency_hz / 2.5 - 1) <= 0.01
    # the 2.5 Hz mode lives on channel c only: its shape says so
    assert np.all(np.abs(result.shapes[hidden][:, :2]) < 0.2)


def test_the_simulated_arm_tip_imu_axes_combine_without_a_spurious_mode():
    """The driven arm's tip IMU as ``sim_node`` publishes it: the in-plane axis (z) moves, the
    out-of-plane x stays exactly 0, y carries gravity and sensor noise. The joint identifier
    finds the arm's one mode (a channel constant over the window has no density: it used to
    make every mode's peak ratio NaN, and no estimate was published), shape on z only."""
    rec = simulate_driven(90, 'ambient', output='tip_acceleration', seed=1)
    z = rec.torque  # the measured output: here the tip acceleration
    y = 9.81 + 0.01 * np.std(z) * np.random.default_rng(2).standard_normal(len(z))
    config = EstimatorConfig(excitation='ambient', ambient_window_s=30.0)
    estimator = AmbientEstimator(config, ['x', 'y', 'z'])
    with np.errstate(divide='raise', invalid='raise'):
        result = estimator.process(rec.t, np.column_stack([np.zeros_like(z), y, z]))
    err = result.estimates.frequency_hz / rec.f_true[0] - 1
    # (13: 30 s in, then the 30 s window every 5 s) and no spurious mode
    assert len(err) >= 10 and np.all(np.abs(err) < 0.05)
    assert np.mean(np.abs(err) < 0.02) >= 0.95
    assert np.all(np.isfinite(result.shapes)) and np.all(np.isfinite(result.shape_std))
    shape = np.median(np.abs(result.shapes), axis=0)
    assert shape[0] == 0.0 and shape[1] < 0.05 and shape[2] > 0.99


def test_correlation_matrices_are_the_direct_sums():
    rng = np.random.default_rng(0)
    y = rng.standard_normal((300, 3))
    r = correlation_matrices(y, 4)
    d = y - y.mean(axis=0)
    for k in range(5):
        direct = d[k:].T @ d[: len(d) - k] / (len(d) - k)
        assert np.allclose(r[k], direct)


def test_one_channel_is_refused_and_bad_samples_are_counted():
    with pytest.raises(ValueError, match='at least 2 channels'):
        AmbientEstimator(CONFIG, ['a'])
    est = AmbientEstimator(CONFIG, ['a', 'b'])
    t = np.arange(10) / FS
    y = np.ones((10, 2))
    y[3, 1] = np.nan
    t[6] = t[5]
    result = est.process(t, y)
    assert len(result) == 0
    c = est.counters
    assert (c['received'], c['skipped_non_finite'], c['skipped_duplicate']) == (10, 1, 1)
    with pytest.raises(ValueError, match='2 channels'):
        est.process(t, np.ones((10, 3)))


def test_close_modes_with_different_shapes_stay_two():
    """``MAC_SAME`` (0.9): two modes 1 % apart (2.0 and 2.02 Hz, closer than MERGE_TOL), each
    on its own channels, are two modes, each near its frequency (merged whatever their shapes,
    one mode at 2.0 Hz is published)."""
    modes = [(2.0, 0.005, 1.0), (2.02, 0.005, 1.0)]
    shapes = np.array([[1.0, 0.0], [0.0, 1.0], [0.5, -0.5]])
    t, y = modal_record(200.0, FS, modes, shapes, snr_db=20.0, seed=0)
    e = AmbientEstimator(CONFIG, ['a', 'b', 'c']).process(t, y).estimates
    late = e.t > 100.0
    assert set(e.mode[late].tolist()) == {1, 2}
    for mode, (f, _, _) in enumerate(modes, 1):
        assert abs(np.median(e.frequency_hz[late & (e.mode == mode)]) / f - 1) < 0.005


@pytest.mark.parametrize('name, factor', [('JOINT_MIN_ROWS', 0.001), ('JOINT_HANKEL', 1000)])
def test_many_channels_keep_enough_lags_in_a_small_hankel_matrix(monkeypatch, name, factor):
    """Ten channels (a 10-storey frame, 300 s at 20 Hz): its six modes below 9 Hz found, each
    in at least 10 analyses within 1 %, the Hankel matrix at most 100 rows (the SVD's cost grows
    as its cube). ``JOINT_MIN_ROWS`` at 0.001x leaves 4 block rows (40 / 10 channels): lags of
    0.2 s at most, a fifth of the 0.89 Hz fundamental's period, which is lost; ``JOINT_HANKEL`` at
    1000x gives every channel count one channel's 40 rows: a 400-row matrix, 3x the CPU for
    the same modes."""
    from vib_estimator.core import ssi

    t, y, freqs, _ = frame_record(300.0, FS, zeta=0.02, snr_db=20.0, seed=1, storeys=10)
    decompose, sizes = ssi.hankel_svd, []
    monkeypatch.setattr(ssi, 'hankel_svd', lambda h, *a: sizes.append(len(h)) or decompose(h, *a))

    def right():
        del sizes[:]
        result = AmbientEstimator(CONFIG, [f'storey{i}' for i in range(10)]).process(t, y)
        f = result.estimates.frequency_hz
        found = [np.sum(np.abs(f / g - 1) <= 0.01) for g in freqs[freqs < 9.0]]
        return min(found) >= 10 and max(sizes) <= 100

    assert right()
    value = getattr(ssi, name) * factor
    monkeypatch.setattr(ssi, name, round(value))
    assert not right()
