# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Single-link flexible arm of Section 5 (Eqs. 19-23), simulated (pure numpy, no rclpy).

Model (Trapero, Sira-Ramirez & Feliu, Section 5.1; Fig. 3):

* tip, Eq. 19 plus structural (Kelvin-Voigt) damping of the bar::

      m L^2 theta_t'' = c (theta_m - theta_t) + b (theta_m' - theta_t'),   b = 2 zeta omega0 m L^2

  so that the clamped-base mode has damping ratio ``zeta`` (Eq. 24 measures it on the signal);
* motor, Eq. 20, written on the motor shaft angle ``n theta_m`` (the paper's hats: motor-side
  quantities, ``theta_m`` being the angle after the gear)::

      k u = J n theta_m'' + v n theta_m' + Gamma_c tanh(n theta_m' / w_c) + Gamma^_coup,
      Gamma^_coup = (c (theta_m - theta_t) + b (theta_m' - theta_t')) / n            (Eq. 21)

  The sign function of Coulomb friction is smoothed by ``tanh`` over a small motor-velocity scale
  ``w_c`` so that the fixed-step RK4 integration stays accurate;
* a digital PD loop on the motor angle (Section 5.2), run at the sample rate and held over the
  sample (zero-order hold), saturated to the servo amplifier's +-10 V::

      u = sat(kp (theta_m* - theta_m) - kd theta_m')

  where the command ``theta_m*`` is a sequence of ramps (:class:`Move`) or, once
  :meth:`ArmSimulator.set_command` is called, the value it was last given (held);
* measurement (``output``): the coupling torque at the base ``Gamma_coup = n Gamma^_coup`` as
  plotted in Fig. 5, i.e. the bending moment ``c (theta_m - theta_t)`` seen by the strain gauges,
  or the tangential acceleration of the tip ``L theta_t''`` an accelerometer there would read;
  plus a constant ``offset`` (a strain-gauge bridge's imbalance), seeded Gaussian noise, and
  quantisation to ``quantum`` (an ADC's step);
* optionally a closed-loop limit cycle (``limit_cycle_voltage`` V): real rigs under a stiff loop
  hold a sustained oscillation at the link's frequency (friction and backlash in the loop,
  ``docs/real_arm.md``); modelled by its describing function, a relay of that amplitude on the
  rate of bending added to the PD voltage::

      u += -V tanh(Gamma_coup' / LIMIT_CYCLE_RATE)

  which moves the base in phase with the tip's velocity and so feeds the link energy at its own
  frequency until the bar's damping takes as much back: a sustained oscillation whose amplitude
  grows with V / zeta and whose frequency stays Eq. 23's (the relay adds no stiffness).

With the stiff PD loop of :class:`ArmParameters` the base barely moves while the bar vibrates, so
the observed frequency is the clamped-base one of Eq. 23 (within 0.02 %, checked by the tests).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Optional, Sequence, Tuple

import numpy as np


def natural_frequency_hz(
    tip_mass_kg: float, stiffness: float = 1.56, length: float = 0.7
) -> float:
    """Eq. 23: ``f0 = sqrt(c / (m L^2)) / (2 pi)`` of the bar clamped at its base, Hz.

    Table 1's bar (c = 1.56 N m/rad, L = 0.7 m) gives 1.64, 1.33 and 1.15 Hz for the 30, 45.55 and
    61.17 g tip masses of Section 5.5.
    """
    if not (tip_mass_kg > 0 and stiffness > 0 and length > 0):
        raise ValueError(
            f'tip mass, stiffness and length must be > 0, got '
            f'{tip_mass_kg!r}, {stiffness!r}, {length!r}'
        )
    return math.sqrt(stiffness / (tip_mass_kg * length**2)) / (2 * math.pi)


@dataclass(frozen=True)
class ArmParameters:
    """Physical parameters of the arm, its drive and its PD loop.

    Bar (Table 1 and Section 5.3 of the paper):
        stiffness: c, N m/rad (Table 1, 1.56).
        length: L, m (Table 1, 700 mm).
        tip_mass_kg: m, kg (45.55 g of Section 5.3).
        damping_ratio: zeta of the bar's mode (Section 5.3 measures 0.004 with Eq. 24).

    Drive (not given in the paper; values of a small DC servo with a 50:1 Harmonic Drive, the
    class of drive of the authors' group's single-link flexible arms):
        inertia: J, motor-side inertia of rotor and gear, kg m^2 (6.87e-5).
        viscous: v, motor-side viscous friction, N m s/rad (1.04e-3).
        motor_gain: k, amplifier gain times torque constant, N m/V (0.21).
        gear_ratio: n (50).
        coulomb: Gamma_c, motor-side Coulomb friction, N m (0.015, ~7 % of the peak torque).
        coulomb_velocity: w_c, motor-shaft velocity over which ``tanh`` smooths the
            friction's sign, rad/s (0.1, well below any velocity of a move: 1 rad/s at the gear is
            50 rad/s here).
        max_voltage: amplifier input range, V (+-10 V, Section 5.2).

    PD loop on theta_m (Section 5.2):
        kp: V/rad (200). Seen at the gear output the loop is a spring of n k kp = 2100 N m/rad,
            1350 times the bar's c, so the base is effectively clamped during a vibration: the
            series-spring shift of the frequency is c / (2 n k kp) < 0.05 %.
        kd: V s/rad (2). With the reflected inertia J n^2 = 0.17 kg m^2 the loop's own mode is at
            ~17 Hz, damped at ~0.8 (with the viscous friction), well above the bar's 1-2 Hz.
    """

    stiffness: float = 1.56
    length: float = 0.7
    tip_mass_kg: float = 0.04555
    damping_ratio: float = 0.004
    inertia: float = 6.87e-5
    viscous: float = 1.04e-3
    motor_gain: float = 0.21
    gear_ratio: float = 50.0
    coulomb: float = 0.015
    coulomb_velocity: float = 0.1
    max_voltage: float = 10.0
    kp: float = 200.0
    kd: float = 2.0

    @property
    def natural_frequency_hz(self) -> float:
        """Eq. 23 for this bar and tip mass."""
        return natural_frequency_hz(self.tip_mass_kg, self.stiffness, self.length)


@dataclass(frozen=True)
class Move:
    """One ramp of the motor command theta_m* (Section 5.3: "a ramp of slope ... and final value").

    From ``start`` s the command moves from its current value towards ``final_angle`` rad at
    ``|slope|`` rad/s and stays there. ``tip_mass_kg``, when given, replaces the tip mass at
    ``start`` (the abrupt change of Section 5.5).
    """

    start: float
    final_angle: float
    slope: float = 1.0
    tip_mass_kg: Optional[float] = None


DEFAULT_NOISE_STD = 0.004  # N m: 1.3 % of the 0.31 N m vibration of experiment_5_3
DEFAULT_QUANTUM = 1e-4  # N m: the resolution of the torques quoted in Section 5.3
#: rate of bending (N m/s) over which the limit cycle's relay switches (tanh): far below the
#: ~2 N m/s of a 0.1 N m vibration at 1.3 Hz, so the relay is a sign
LIMIT_CYCLE_RATE = 1e-3
#: what :class:`ArmSimulator` measures
OUTPUTS = ('torque', 'tip_acceleration')


class ArmSimulator:
    """Sample-by-sample simulation of the arm: fixed-step RK4 with ``substeps`` per sample.

    The PD voltage is computed once per sample and held (digital controller at ``rate_hz``,
    500 Hz = the 2 ms sample time of Section 5.2). ``schedule`` is a sequence of :class:`Move`
    applied in order of ``start`` (those at 0 s already by the constructor); the arm starts at rest
    at angle 0.

    ``output`` is what :meth:`step` measures: ``'torque'`` (N m) or ``'tip_acceleration'``
    (``L theta_t''``, m/s^2). ``noise_std`` and ``quantum`` are in N m of coupling torque; for the
    acceleration they are divided by ``m L`` (the torque-to-acceleration factor of Eq. 19), so
    both outputs have the same signal-to-noise ratio; so is ``offset`` (N m, added before the
    noise). ``limit_cycle_voltage`` (V, 0 = off): the closed-loop limit cycle of the module
    docstring.
    """

    def __init__(
        self,
        params: ArmParameters = ArmParameters(),
        rate_hz: float = 500.0,
        noise_std: float = DEFAULT_NOISE_STD,
        quantum: float = DEFAULT_QUANTUM,
        seed: int = 0,
        schedule: Sequence[Move] = (Move(0.0, 1.0),),
        substeps: int = 8,
        output: str = 'torque',
        offset: float = 0.0,
        limit_cycle_voltage: float = 0.0,
    ):
        if not rate_hz > 0 or substeps < 1 or noise_std < 0 or quantum < 0:
            raise ValueError('rate_hz and substeps must be > 0, noise_std and quantum >= 0')
        if not (math.isfinite(offset) and 0 <= limit_cycle_voltage <= params.max_voltage):
            raise ValueError(
                f'offset must be finite and limit_cycle_voltage in [0, '
                f'{params.max_voltage:g}] V, got {offset!r}, {limit_cycle_voltage!r}'
            )
        self.offset = float(offset)
        self.limit_cycle_voltage = float(limit_cycle_voltage)
        if output not in OUTPUTS:
            raise ValueError(f'output must be one of {", ".join(OUTPUTS)}, got {output!r}')
        self.output = output
        self.commanded = False  # set_command took over from the schedule
        self.params = params
        self.rate_hz = float(rate_hz)
        self.noise_std = float(noise_std)
        self.quantum = float(quantum)
        self.seed = seed
        self._rng = np.random.default_rng(seed)
        self._moves = sorted(schedule, key=lambda mv: mv.start)
        self._next_move = 0
        self._substeps = int(substeps)
        self._h = 1.0 / (self.rate_hz * self._substeps)
        self._k = 0  # samples produced so far
        self._x = [0.0, 0.0, 0.0, 0.0]  # theta_m, theta_m', theta_t, theta_t'
        self._command = 0.0
        self._target = 0.0
        self._slope = 0.0
        self.set_tip_mass(params.tip_mass_kg)
        self._apply_moves(0.0)  # so that f_true is the schedule's from the start

    @property
    def t(self) -> float:
        """Time of the next sample, s."""
        return self._k / self.rate_hz

    @property
    def f_true(self) -> float:
        """Eq. 23 frequency of the current tip mass, Hz."""
        return self.params.natural_frequency_hz

    @property
    def command(self) -> float:
        """The current motor command theta_m*, rad."""
        return self._command

    @property
    def motor_angle(self) -> float:
        """The motor angle theta_m now, rad."""
        return self._x[0]

    def set_tip_mass(self, m: float) -> None:
        """Change the tip mass abruptly (Section 5.5); the bar's state is kept."""
        p = replace(self.params, tip_mass_kg=float(m))
        f0 = p.natural_frequency_hz  # validates m
        self.params = p
        inertia = m * p.length**2
        self._tip_inertia = inertia
        self._bar_damping = 2 * p.damping_ratio * (2 * math.pi * f0) * inertia

    def set_command(self, angle: float) -> None:
        """Hold the motor command at ``angle`` rad from the next sample on; the schedule's ramps
        stop for good (its tip-mass changes still apply)."""
        angle = float(angle)
        if not math.isfinite(angle):
            raise ValueError(f'command must be finite, got {angle!r}')
        self.commanded = True
        self._command = self._target = angle

    def _apply_moves(self, t: float) -> None:
        while self._next_move < len(self._moves) and self._moves[self._next_move].start <= t:
            mv = self._moves[self._next_move]
            self._next_move += 1
            if not self.commanded:
                self._target = float(mv.final_angle)
                self._slope = abs(float(mv.slope))
            if mv.tip_mass_kg is not None:
                self.set_tip_mass(mv.tip_mass_kg)

    def _measure(self, x, u) -> float:
        """The noise-free output at state ``x`` under voltage ``u``, and its noise scale."""
        p = self.params
        if self.output == 'torque':
            return p.stiffness * (x[0] - x[2]) + self.offset, 1.0
        scale = 1.0 / (p.tip_mass_kg * p.length)
        return p.length * self._derivatives(x, u)[3] + scale * self.offset, scale

    def _limit_cycle(self, x) -> float:
        """The limit cycle's relay voltage at state ``x`` (0 when off), module docstring."""
        if not self.limit_cycle_voltage:
            return 0.0
        bending_rate = self.params.stiffness * (x[1] - x[3])
        return -self.limit_cycle_voltage * math.tanh(bending_rate / LIMIT_CYCLE_RATE)

    def _derivatives(self, x, u):
        p = self.params
        qm, wm, qt, wt = x
        bend = p.stiffness * (qm - qt) + self._bar_damping * (wm - wt)
        n = p.gear_ratio
        motor_torque = (
            p.motor_gain * u
            - p.viscous * n * wm
            - p.coulomb * math.tanh(n * wm / p.coulomb_velocity)
            - bend / n
        )
        return (wm, motor_torque / (p.inertia * n), wt, bend / self._tip_inertia)

    def step(self) -> Tuple[float, float, float]:
        """Advance one sample: ``(t, measured output, true f0 in Hz)``; the output is the coupling
        torque in N m or the tip acceleration in m/s^2 (``output``).

        The sample at ``t`` is taken before the state advances to ``t + 1/rate_hz``.
        """
        t = self.t
        self._apply_moves(t)
        p = self.params
        x = self._x
        u = p.kp * (self._command - x[0]) - p.kd * x[1] + self._limit_cycle(x)
        u = min(max(u, -p.max_voltage), p.max_voltage)
        y, scale = self._measure(x, u)
        if self.noise_std:
            y += scale * self.noise_std * self._rng.standard_normal()
        if self.quantum:
            y = scale * self.quantum * round(y / (scale * self.quantum))
        f_true = self.f_true
        h = self._h
        for _ in range(self._substeps):
            k1 = self._derivatives(x, u)
            k2 = self._derivatives([a + 0.5 * h * b for a, b in zip(x, k1)], u)
            k3 = self._derivatives([a + 0.5 * h * b for a, b in zip(x, k2)], u)
            k4 = self._derivatives([a + h * b for a, b in zip(x, k3)], u)
            x = [
                a + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4)
                for a, b1, b2, b3, b4 in zip(x, k1, k2, k3, k4)
            ]
        self._x = x
        return self._advance_command(t, y, f_true)

    def _advance_command(self, t: float, y: float, f_true: float) -> Tuple[float, float, float]:
        """Move the scheduled ramp one sample on (a held command stays) and count the sample."""
        step = self._slope / self.rate_hz
        err = self._target - self._command
        self._command = (
            self._target if abs(err) <= step else self._command + math.copysign(step, err)
        )
        self._k += 1
        return t, y, f_true


@dataclass
class Recording:
    """A simulated record, one entry per sample: time (s), measured torque (N m), Eq. 23 f0
    (Hz)."""

    t: np.ndarray
    torque: np.ndarray
    f_true: np.ndarray


def simulate(
    duration: float,
    schedule: Sequence[Move] = (Move(0.0, 1.0),),
    params: ArmParameters = ArmParameters(),
    rate_hz: float = 500.0,
    noise_std: float = DEFAULT_NOISE_STD,
    seed: int = 0,
    quantum: float = DEFAULT_QUANTUM,
    output: str = 'torque',
    offset: float = 0.0,
    limit_cycle_voltage: float = 0.0,
) -> Recording:
    """Simulate ``duration`` s of the arm under ``schedule`` and return the :class:`Recording`
    (its ``torque`` column holds the ``output``); ``offset``, ``quantum`` and
    ``limit_cycle_voltage``: :class:`ArmSimulator`."""
    sim = ArmSimulator(
        params,
        rate_hz,
        noise_std,
        quantum,
        seed,
        schedule,
        output=output,
        offset=offset,
        limit_cycle_voltage=limit_cycle_voltage,
    )
    rows = np.array([sim.step() for _ in range(int(round(duration * rate_hz)))]).reshape(-1, 3)
    return Recording(rows[:, 0].copy(), rows[:, 1].copy(), rows[:, 2].copy())


#: Section 5.5's tip masses, kg (Eq. 23: 1.64, 1.33, 1.15 Hz)
MASSES_5_5 = (0.030, 0.04555, 0.06117)


def schedule_5_5(
    seconds_per_mass: float = 6.0, final_angles: Sequence[float] = (0.3, 1.0, 1.5)
) -> Tuple[Move, ...]:
    """Section 5.5's experiment: each mass of :data:`MASSES_5_5` for ``seconds_per_mass`` s.

    Each segment fits its mass, then moves the command from 0 to its entry of ``final_angles``,
    alternately up and down (0 -> a1 -> a1 - a2 -> ...), in a 1 s ramp (slope = |step|, like
    Section 5.3's ramp of slope and final value one). The residual vibration is then proportional
    to the step: about 0.08, 0.32 and 0.29 N m, so the first mass has the lowest signal-to-noise
    ratio, as in Fig. 7.
    """
    moves, angle = [], 0.0
    for i, (m, step) in enumerate(zip(MASSES_5_5, final_angles)):
        angle += step if i % 2 == 0 else -step
        moves.append(Move(i * seconds_per_mass, angle, step, m))
    return tuple(moves)


def experiment_5_3(seed: int = 0) -> Recording:
    """Section 5.3 / Fig. 5: 45.55 g at the tip, command a ramp of slope 1 to 1 rad, 10 s."""
    return simulate(10.0, (Move(0.0, 1.0, 1.0, 0.04555),), seed=seed)


def experiment_5_5(seed: int = 0) -> Recording:
    """Section 5.5 / Fig. 7: 30 -> 45.55 -> 61.17 g, 6 s each, of increasing vibration
    amplitude."""
    return simulate(18.0, schedule_5_5(), seed=seed)


#: how a :class:`DrivenArmSimulator` drives the arm: scheduled ramps only (``moves``), a
#: band-limited random motor command (``random``) or a broadband disturbance torque at the tip
#: (``ambient``)
EXCITATIONS = ('moves', 'random', 'ambient')


class DrivenArmSimulator(ArmSimulator):
    """The arm in operation, never at rest (issue 20): an :class:`ArmSimulator` whose motor
    command is, with ``excitation = 'random'``, a random walk of the angle low-pass filtered at
    ``bandwidth_hz`` (first order, ``level`` rad of standard deviation), or whose tip receives,
    with ``'ambient'``, a white disturbance torque of standard deviation ``level`` N m, held over
    each sample (``moves``: the schedule's ramps only, as the base class). Seeded (``seed + 1``,
    independent of the measurement noise's stream)."""

    def __init__(
        self,
        params: ArmParameters = ArmParameters(),
        *args,
        excitation: str = 'ambient',
        level: float = 0.02,
        bandwidth_hz: float = 2.0,
        **kwargs,
    ):
        """``params``, ``args``, ``kwargs``: those of :class:`ArmSimulator` (pass
        ``schedule=(Move(0.0, 0.0),)`` to hold the motor at 0 rad: it drives the arm by itself)."""
        super().__init__(params, *args, **kwargs)
        if excitation not in EXCITATIONS:
            raise ValueError(
                f'excitation must be one of {", ".join(EXCITATIONS)}, got {excitation!r}'
            )
        if not (level >= 0 and bandwidth_hz > 0):
            raise ValueError('level must be >= 0 and bandwidth_hz > 0')
        self.excitation = excitation
        self.level = float(level)
        self._drive = np.random.default_rng(self.seed + 1)
        self._pole = math.exp(-2 * math.pi * bandwidth_hz / self.rate_hz)
        self._disturbance = 0.0
        self._random_angle = 0.0

    def _derivatives(self, x, u):
        wm, am, wt, at = super()._derivatives(x, u)
        return wm, am, wt, at + self._disturbance / self._tip_inertia

    def step(self) -> Tuple[float, float, float]:
        if self.excitation == 'ambient':
            self._disturbance = self.level * self._drive.standard_normal()
        elif self.excitation == 'random':
            # first-order low-pass of white noise, scaled to a standard deviation of ``level``
            a = self._pole
            self._random_angle = (
                a * self._random_angle
                + math.sqrt(1 - a * a) * self.level * self._drive.standard_normal()
            )
            self.set_command(self._random_angle)
        return super().step()


def simulate_driven(
    duration: float,
    excitation: str = 'ambient',
    level: float = 0.02,
    params: ArmParameters = ArmParameters(),
    rate_hz: float = 500.0,
    noise_std: float = DEFAULT_NOISE_STD,
    seed: int = 0,
    output: str = 'torque',
) -> Recording:
    """``duration`` s of the arm driven by ``excitation`` (:class:`DrivenArmSimulator`)."""
    sim = DrivenArmSimulator(
        params,
        rate_hz,
        noise_std,
        DEFAULT_QUANTUM,
        seed,
        (Move(0.0, 0.0),),
        output=output,
        excitation=excitation,
        level=level,
    )
    rows = np.array([sim.step() for _ in range(int(round(duration * rate_hz)))]).reshape(-1, 3)
    return Recording(rows[:, 0].copy(), rows[:, 1].copy(), rows[:, 2].copy())


def back_and_forth(
    seconds: float, every: float, angle: float, slope: float, jitter: float, seed: int = 0
) -> Recording:
    """``seconds`` s at 500 Hz of the arm moved without rest (a pick-and-place cycle): a ramp of
    ``slope`` rad/s every ``every`` s to +-``angle`` rad in turn, the angle and the time between
    moves each jittered by up to ``jitter`` (relative; 0: a strictly periodic cycle), seeded."""
    rng = np.random.default_rng(seed + 100)
    moves, t, k = [], 0.0, 0
    while t < seconds:
        moves.append(Move(t, angle * (-1) ** k * (1 + jitter * rng.uniform(-1, 1)), slope))
        t += every * (1 + jitter * rng.uniform(-0.5, 0.5))
        k += 1
    sim = DrivenArmSimulator(rate_hz=500.0, seed=seed, schedule=tuple(moves), excitation='moves')
    rows = np.array([sim.step() for _ in range(int(seconds * 500.0))])
    return Recording(rows[:, 0].copy(), rows[:, 1].copy(), rows[:, 2].copy())
