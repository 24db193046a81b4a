"""The simulated flexible arm against the paper's model: Eq. 23 frequency, Eq. 24 damping, seeds."""
from __future__ import annotations

import math

import numpy as np
import pytest

from vib_estimator.sim.arm_model import (MASSES_5_5, ArmParameters, ArmSimulator, Move,
                                     experiment_5_3, experiment_5_5, natural_frequency_hz,
                                     schedule_5_5, simulate)


def free_vibration(m, duration=12.0):
    """Noise-free coupling torque after a 1 s ramp to 1 rad (the Section 5.3 move), from t = 2 s."""
    rec = simulate(duration, (Move(0.0, 1.0, 1.0, m),), noise_std=0.0, quantum=0.0)
    keep = rec.t >= 2.0
    return rec.t[keep], rec.torque[keep]


def upward_crossings(t, y):
    """Linearly interpolated times of the upward zero crossings of y."""
    i = np.flatnonzero((y[:-1] < 0) & (y[1:] >= 0))
    return t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i])


def test_eq23_frequencies_of_section_5_5():
    got = [round(natural_frequency_hz(m), 2) for m in MASSES_5_5]
    assert got == [1.64, 1.33, 1.15]
    assert ArmParameters().natural_frequency_hz == pytest.approx(1.3306, abs=1e-4)
    with pytest.raises(ValueError):
        natural_frequency_hz(0.0)


@pytest.mark.parametrize('m', MASSES_5_5)
def test_free_vibration_frequency_matches_eq23(m):
    t, y = free_vibration(m)
    crossings = upward_crossings(t, y - y.mean())
    f = (len(crossings) - 1) / (crossings[-1] - crossings[0])
    assert f == pytest.approx(natural_frequency_hz(m), rel=1e-3)


@pytest.mark.parametrize('m', MASSES_5_5)
def test_eq24_on_simulated_peaks_recovers_damping(m):
    t, y = free_vibration(m)
    peaks = 1 + np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:]))
    f0 = natural_frequency_hz(m)
    # Eq. 24 between the first and the last peak of the record
    t1, t2 = t[peaks[0]], t[peaks[-1]]
    zeta = -math.log(y[peaks[-1]] / y[peaks[0]]) / (2 * math.pi * f0 * (t2 - t1))
    assert zeta == pytest.approx(ArmParameters().damping_ratio, rel=0.1)


def test_seeded_runs_are_reproducible():
    a, b, c = experiment_5_3(seed=3), experiment_5_3(seed=3), experiment_5_3(seed=4)
    np.testing.assert_array_equal(a.torque, b.torque)
    assert not np.array_equal(a.torque, c.torque)
    assert len(a.t) == 5000 and np.all(a.f_true == natural_frequency_hz(0.04555))


def test_noise_and_quantisation():
    quiet = simulate(2.0, noise_std=0.0, quantum=0.0)
    noisy = simulate(2.0, noise_std=0.004, quantum=1e-4, seed=1)
    residual = noisy.torque - quiet.torque
    assert np.std(residual) == pytest.approx(0.004, rel=0.1)
    np.testing.assert_allclose(noisy.torque / 1e-4, np.round(noisy.torque / 1e-4), atol=1e-6)


def test_experiment_5_5_masses_and_signal_to_noise():
    rec = experiment_5_5()
    edges = [0.0, 6.0, 12.0, 18.0]
    amplitudes = []
    for m, t0, t1 in zip(MASSES_5_5, edges, edges[1:]):
        seg = (rec.t >= t0) & (rec.t < t1)
        assert np.all(rec.f_true[seg] == natural_frequency_hz(m))
        late = (rec.t >= t0 + 2.0) & (rec.t < t1)
        amplitudes.append(np.percentile(np.abs(rec.torque[late] - rec.torque[late].mean()), 99))
    assert amplitudes[0] < 0.5 * min(amplitudes[1:])   # first mass: lowest SNR (Fig. 7)


def test_schedule_and_abrupt_mass_change():
    assert [mv.tip_mass_kg for mv in schedule_5_5()] == list(MASSES_5_5)
    sim = ArmSimulator(noise_std=0.0, schedule=(Move(0.0, 0.5, 0.5), Move(0.5, 0.0, 2.0)))
    samples = [sim.step() for _ in range(400)]  # 0.25 rad at 0.5 s, back at 0.625 s
    assert sim.command == pytest.approx(0.0)
    assert samples[0][0] == 0.0 and samples[-1][0] == pytest.approx(399 / 500)
    sim.set_tip_mass(0.030)
    assert sim.step()[2] == pytest.approx(natural_frequency_hz(0.030))


def test_commands_take_over_from_the_schedule_but_not_its_masses():
    """set_command holds the motor reference; the schedule's later ramps no longer move it, its
    tip-mass changes still apply."""
    sim = ArmSimulator(schedule=(Move(0.0, 1.0, 1.0, 0.03), Move(1.0, -2.0, 1.0, 0.06117)),
                       noise_std=0.0)
    for _ in range(100):
        sim.step()
    assert 0 < sim.command < 0.25                    # the first ramp, 0.2 s in
    sim.set_command(0.5)
    assert sim.command == 0.5 and sim.commanded
    for _ in range(1500):                            # past the second move's start
        sim.step()
    assert sim.command == 0.5
    assert sim.params.tip_mass_kg == 0.06117         # the mass change applied
    assert sim._x[0] == pytest.approx(0.5, abs=1e-3)  # the PD loop holds the motor there
    with pytest.raises(ValueError):
        sim.set_command(float('nan'))


def test_tip_acceleration_output():
    """L theta_t'' = (c (theta_m - theta_t) + b (theta_m' - theta_t')) / (m L): within the small
    damping term of the torque over m L; same frequency; noise scaled by 1 / (m L)."""
    m, length = 0.04555, 0.7
    torque = simulate(6.0, (Move(0.0, 1.0, 1.0, m),), noise_std=0.0, quantum=0.0)
    accel = simulate(6.0, (Move(0.0, 1.0, 1.0, m),), noise_std=0.0, quantum=0.0,
                     output='tip_acceleration')
    free = torque.t >= 2.0
    scaled = torque.torque[free] / (m * length)
    amplitude = np.max(np.abs(scaled))
    assert np.max(np.abs(accel.torque[free] - scaled)) < 0.03 * amplitude
    crossings = upward_crossings(accel.t[free], accel.torque[free])
    f = (len(crossings) - 1) / (crossings[-1] - crossings[0])
    assert f == pytest.approx(natural_frequency_hz(m), rel=1e-3)
    noisy = simulate(2.0, noise_std=0.004, quantum=0.0, seed=1, output='tip_acceleration')
    quiet = simulate(2.0, noise_std=0.0, quantum=0.0, output='tip_acceleration')
    assert np.std(noisy.torque - quiet.torque) == pytest.approx(0.004 / (m * length), rel=0.1)
    with pytest.raises(ValueError, match='output must be'):
        ArmSimulator(output='strain')
