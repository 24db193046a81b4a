# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``sim_node``: the flexible arm of Section 5 (:mod:`vib_estimator.sim.arm_model`) as a ROS 2
node.

Publishes the measured coupling torque (Eq. 21, scaled as in Fig. 5) as
``geometry_msgs/WrenchStamped`` on ``coupling_torque`` (``torque.z``) at ``rate_hz`` -- or, with
``output_type`` ``sensor_msgs/msg/Imu``, the tip acceleration ``L theta_t''`` as
``linear_acceleration.z`` on ``tip_imu`` -- and the Eq. 23 frequency of the current tip mass as
``std_msgs/Float64`` on ``vibration/ground_truth`` (transient local, so a late subscriber gets the
current value) at start and whenever it changes.

Realism of a real rig (all off by default, read-only): ``offset`` (a strain-gauge offset),
``quantum`` (an ADC's step) and ``limit_cycle_voltage`` (a sustained closed-loop oscillation at
the link's frequency), :class:`vib_estimator.sim.arm_model.ArmSimulator`; ``docs/real_arm.md``.

Commands: ``position_command`` (``std_msgs/Float64``, the motor angle reference in rad) is held
from the next sample until the next message; the first one takes over from the motion schedule
for good (the schedule's tip-mass changes still apply).

Time: with ``speed`` = 1 the node runs in real time and stamps sample ``k`` with
``start + k / rate_hz`` (``start`` read from the node clock), so stamps are exactly periodic. With
any other ``speed``, or with ``publish_clock`` set, it runs a simulated clock, ``speed`` times
faster (or slower) than real time, publishes it on ``/clock`` and stamps samples with it
(subscribers then set ``use_sim_time``); the simulated clock starts at :data:`SIM_TIME_ORIGIN_NS`
(1 s) because ROS takes a zero stamp as unset.
Samples are produced in batches by a 1 kHz steady-clock timer, as many as are due, so that high
speeds work. Setting ``tip_mass_kg`` while running changes the frequency abruptly, as in
Section 5.5. ``duration`` makes the node exit 0 after that much simulated time, and
``wait_for_subscribers`` holds the start until the consumers are matched (the demo and the tests
use both); ``wait_for_command`` until the first command. ``lockstep`` (simulated time) makes each
batch wait for a command answering the previous ``/clock``, so a closed loop through other nodes
behaves the same at any speed and load; ``pause_at`` (simulated time, settable) holds the arm at
a simulated time until it is raised, so a commander outside that loop (the shaping demo's moves)
acts at the times it planned, however far behind it is.
"""

from __future__ import annotations

import math
import sys
import time
from typing import List, Sequence, Tuple

from geometry_msgs.msg import WrenchStamped
from rcl_interfaces.msg import ParameterType, SetParametersResult
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock as ClockMsg
from sensor_msgs.msg import Imu
from std_msgs.msg import Float64

from ..errors import StartupError
from ..io.fields import IMU, WRENCH_STAMPED, normalise_type
from ..sim.arm_model import (
    DEFAULT_NOISE_STD,
    DEFAULT_QUANTUM,
    EXCITATIONS,
    ArmParameters,
    ArmSimulator,
    DrivenArmSimulator,
    Move,
    natural_frequency_hz,
)
from .parameters import declare, descriptor, warn_unused_params_files
from .runner import run

# wall-clock rate of the publishing timer: a command takes effect at the start of the next batch,
# so a tick of 1 ms keeps that within 10 samples (20 ms simulated) at 10x (input shaping needs it)
TICK_HZ = 1000.0
# A tick produces at most the larger of MAX_BATCH_SECONDS of simulated time and BATCH_TICKS ticks'
# worth: after a longer stall the node falls behind its speed (and says so) rather than bursting.
MAX_BATCH_SECONDS = 0.1
BATCH_TICKS = 4
MIN_SAMPLES_PER_PERIOD = 20  # a tip mass is refused if f0 (Eq. 23) leaves fewer samples a period
SIM_TIME_ORIGIN_NS = 1_000_000_000  # stamp of the first sample in simulated time (0 means unset)
# lockstep: a batch is at most this much simulated time, and waits at most this long (wall) for
# the command answering the previous batch's /clock
LOCKSTEP_BATCH_SECONDS = 0.02
LOCKSTEP_TIMEOUT = 1.0
#: why lockstep and pause_at are refused in real time
NEEDS_SIM_TIME = 'needs simulated time: speed other than 1 or publish_clock'
#: physical range of the tip mass, kg (Table 1's bar: 45.55 g; 10 kg gives f0 = 0.09 Hz)
TIP_MASS_RANGE_KG = (0.001, 10.0)
SCHEDULE_FIELDS = 4  # start, final_angle, slope, tip_mass_kg (0 = unchanged)
#: output_type -> (message class, topic)
OUTPUTS = {WRENCH_STAMPED: (WrenchStamped, 'coupling_torque'), IMU: (Imu, 'tip_imu')}

GROUND_TRUTH_QOS = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)


def schedule_to_array(schedule: Sequence[Move]) -> List[float]:
    """The ``schedule`` parameter for a sequence of moves (see :func:`schedule_from_array`)."""
    out: List[float] = []
    for mv in schedule:
        out += [
            float(mv.start),
            float(mv.final_angle),
            float(mv.slope),
            float(mv.tip_mass_kg or 0.0),
        ]
    return out


def schedule_from_array(values: Sequence[float]) -> List[Move]:
    """Moves from the flat ``schedule`` parameter; raises ``ValueError`` saying what is wrong.

    Groups of four numbers ``[start s, final_angle rad, slope rad/s, tip_mass_kg]``, with starts
    non-decreasing, slopes > 0 and tip_mass_kg 0 (= unchanged) or > 0.
    """
    values = [float(v) for v in values]
    if len(values) % SCHEDULE_FIELDS:
        raise ValueError(
            f'schedule must hold groups of {SCHEDULE_FIELDS} numbers [start, '
            f'final_angle, slope, tip_mass_kg], got {len(values)} numbers'
        )
    if not all(math.isfinite(v) for v in values):
        raise ValueError('schedule must hold finite numbers')
    moves = []
    for i in range(0, len(values), SCHEDULE_FIELDS):
        start, angle, slope, mass = values[i : i + SCHEDULE_FIELDS]
        if start < 0 or (moves and start < moves[-1].start):
            raise ValueError(
                f'schedule move {i // SCHEDULE_FIELDS}: start {start} must be >= 0 '
                'and not before the previous move'
            )
        if slope <= 0:
            raise ValueError(
                f'schedule move {i // SCHEDULE_FIELDS}: slope must be > 0, got {slope}'
            )
        if mass < 0:
            raise ValueError(
                f'schedule move {i // SCHEDULE_FIELDS}: tip_mass_kg must be 0 '
                f'(unchanged) or > 0, got {mass}'
            )
        moves.append(Move(start, angle, slope, mass if mass > 0 else None))
    return moves


PARAMETERS = {
    # name: (default, descriptor)
    'tip_mass_kg': (
        ArmParameters.tip_mass_kg,
        descriptor(
            'tip mass m of Eqs. 19/23, kg; changing it while running changes the frequency '
            'abruptly (Section 5.5)',
            TIP_MASS_RANGE_KG,
        ),
    ),
    'rate_hz': (
        500.0,
        descriptor(
            'sample rate of coupling_torque, Hz (Section 5.2: 2 ms)',
            (10.0, 10000.0),
            read_only=True,
        ),
    ),
    'speed': (
        1.0,
        descriptor(
            'simulated seconds per wall-clock second; other than 1 the node '
            'publishes /clock and stamps in simulated time from 1 s',
            (0.01, 1000.0),
            read_only=True,
        ),
    ),
    'publish_clock': (
        False,
        descriptor(
            'stamp in simulated time from 1 s and publish it on /clock even at speed 1 (always so '
            'at any other speed)',
            read_only=True,
        ),
    ),
    'damping_ratio': (
        ArmParameters.damping_ratio,
        descriptor(
            'damping ratio zeta of the bar mode (Eq. 24; 0.004 in Section 5.3)',
            (0.0, 0.5),
            read_only=True,
        ),
    ),
    'noise_std': (
        DEFAULT_NOISE_STD,
        descriptor('standard deviation of the strain-gauge noise on the torque, N m', (0.0, 10.0)),
    ),
    'offset': (
        0.0,
        descriptor(
            "constant offset of the measurement (a strain-gauge bridge's imbalance), N m of "
            'coupling torque (the tip acceleration: divided by m L); real rigs have one, the '
            "paper's sinusoid model does not (docs/real_arm.md)",
            (-10.0, 10.0),
            read_only=True,
        ),
    ),
    'quantum': (
        DEFAULT_QUANTUM,
        descriptor(
            "quantisation step of the measurement (an ADC's resolution), N m of coupling torque "
            "(0 = none); a real rig's can be a tenth of the vibration's amplitude",
            (0.0, 1.0),
            read_only=True,
        ),
    ),
    'limit_cycle_voltage': (
        0.0,
        descriptor(
            'closed-loop limit cycle: amplitude of a relay on the rate of bending added to the PD '
            'voltage (the describing function of friction and backlash in a stiff loop), V; the '
            'link then holds a sustained oscillation at its own frequency, ~1 N m per V (0 = off)',
            (0.0, 10.0),
            read_only=True,
        ),
    ),
    'seed': (0, descriptor('seed of the noise generator', (0, 2**31 - 1), read_only=True)),
    'frame_id': (
        'arm_base',
        descriptor('frame_id of the coupling_torque headers', read_only=True),
    ),
    'schedule': (
        [0.0, 1.0, 1.0, 0.0],
        descriptor(
            'motor command as flat groups [start s, final_angle rad, slope rad/s, tip_mass_kg '
            '(0 = unchanged)]: from start, ramp towards final_angle at slope and set the tip '
            'mass; default: the Section 5.3 ramp of slope 1 to 1 rad',
            read_only=True,
            type=ParameterType.PARAMETER_DOUBLE_ARRAY,
        ),
    ),
    'wait_for_subscribers': (
        0,
        descriptor(
            'the simulation starts when the output topic has this many subscribers (0 = at once), '
            'so that a sped-up run loses no sample to discovery',
            (0, 1000),
            read_only=True,
        ),
    ),
    'duration': (
        0.0,
        descriptor(
            'simulated seconds after which the node exits 0 (0 = run forever)',
            (0.0, 1e9),
            read_only=True,
        ),
    ),
    'wait_for_command': (
        False,
        descriptor(
            'the simulation starts when the first position_command has arrived (in simulated time '
            'the start of the clock is published meanwhile, so a use_sim_time commander can run)',
            read_only=True,
        ),
    ),
    'lockstep': (
        False,
        descriptor(
            'in simulated time, once commands flow, each batch of samples (at most '
            f'{LOCKSTEP_BATCH_SECONDS * 1e3:g} ms) waits for a position_command received after '
            'the previous /clock (at most 1 s): a commander answering every /clock (shaper_node '
            'with use_sim_time) then acts at the simulated times it computed for, however loaded '
            'the machine; the run goes as fast as that round trip allows, at most speed',
            read_only=True,
        ),
    ),
    'pause_at': (
        0.0,
        descriptor(
            'simulated time only: once it has published the sample at (or just after) this '
            'simulated time, s, the arm holds (no sample, no /clock) until the parameter is '
            'raised or set to 0 (= never); settable: a commander sets it to its next event, '
            'acts there and raises it, so it acts at the times it planned however loaded the '
            'machine',
            (0.0, 1e9),
        ),
    ),
    'output_type': (
        WRENCH_STAMPED,
        descriptor(
            'message of the measurement: geometry_msgs/msg/WrenchStamped (coupling torque, '
            'torque.z, on coupling_torque) or sensor_msgs/msg/Imu (tip acceleration, '
            'linear_acceleration.z, on tip_imu)',
            read_only=True,
        ),
    ),
    'excitation': (
        'moves',
        descriptor(
            "what drives the arm: moves (the schedule's ramps), random (a band-limited random "
            'motor command of excitation_level rad std, 2 Hz) or ambient (a white disturbance '
            'torque at the tip of excitation_level N m std): the arm never at rest '
            '(docs/operation.md)',
            read_only=True,
        ),
    ),
    'excitation_level': (
        0.0,
        descriptor(
            'excitation random: rad; ambient: N m (0 = the default: 0.3 rad, 0.02 N m)',
            (0.0, 100.0),
            read_only=True,
        ),
    ),
}
#: ``excitation_level`` 0 means these
DEFAULT_EXCITATION_LEVEL = {'random': 0.3, 'ambient': 0.02}


def make_simulator(p, schedule, output_type: str) -> ArmSimulator:
    """The arm of the parameters ``p`` (name -> value): an :class:`ArmSimulator` following
    ``schedule``, or with ``excitation`` other than ``moves`` a :class:`DrivenArmSimulator` that
    never rests; :class:`StartupError` for an unknown excitation."""
    if p['excitation'] not in EXCITATIONS:
        raise StartupError(
            f'excitation must be one of {", ".join(EXCITATIONS)}, got {p["excitation"]!r}'
        )
    driven = {}
    if p['excitation'] != 'moves':
        level = p['excitation_level'] or DEFAULT_EXCITATION_LEVEL[p['excitation']]
        driven = {'excitation': p['excitation'], 'level': level}
    return (DrivenArmSimulator if driven else ArmSimulator)(
        ArmParameters(tip_mass_kg=p['tip_mass_kg'], damping_ratio=p['damping_ratio']),
        rate_hz=p['rate_hz'],
        noise_std=p['noise_std'],
        quantum=p['quantum'],
        seed=p['seed'],
        schedule=schedule,
        output='torque' if output_type == WRENCH_STAMPED else 'tip_acceleration',
        offset=p['offset'],
        limit_cycle_voltage=p['limit_cycle_voltage'],
        **driven,
    )


class SimNode(Node):
    """The simulated arm publishing ``coupling_torque`` (or ``tip_imu``) and
    ``vibration/ground_truth``, following ``position_command`` once it arrives."""

    def __init__(self, **kwargs):
        super().__init__('sim_node', **kwargs)
        for name, (default, desc) in PARAMETERS.items():
            declare(self, name, default, desc)
        warn_unused_params_files(self, kwargs.get('cli_args'))
        p = {name: self.get_parameter(name).value for name in PARAMETERS}
        try:
            schedule = schedule_from_array(p['schedule'])
        except ValueError as err:
            raise StartupError(str(err)) from None
        if not p['frame_id']:
            raise StartupError('frame_id must not be empty')
        self._output_type = normalise_type(p['output_type'])
        if self._output_type not in OUTPUTS:
            raise StartupError(
                f'output_type must be one of {", ".join(OUTPUTS)}, got {p["output_type"]!r}'
            )
        self._rate = p['rate_hz']
        masses = [p['tip_mass_kg']] + [mv.tip_mass_kg for mv in schedule if mv.tip_mass_kg]
        check = self._validate([Parameter('tip_mass_kg', value=m) for m in masses])
        if not check.successful:
            raise StartupError(check.reason)
        self.add_on_set_parameters_callback(self._validate)
        self.add_post_set_parameters_callback(self._apply)

        self.exit_code = 0
        self.finished = False
        self._speed = p['speed']
        self._sim_time = self._speed != 1.0 or p['publish_clock']
        self._duration = p['duration']
        self._wait_for_subscribers = p['wait_for_subscribers']
        self._wait_for_command = p['wait_for_command']
        self._lockstep = p['lockstep']
        if self._lockstep and not self._sim_time:
            raise StartupError(f'lockstep {NEEDS_SIM_TIME}')
        if p['pause_at'] > 0 and not self._sim_time:
            raise StartupError(f'pause_at {NEEDS_SIM_TIME}')
        self._pause_at = p['pause_at']
        self._paused_since = None  # monotonic time the arm began holding at pause_at
        self._answered = True  # a command arrived since the last /clock (lockstep)
        self._clock_at = 0.0  # monotonic time of the last batch's /clock
        self.lockstep_timeouts = 0
        self._sim = make_simulator(p, schedule, self._output_type)
        self._sync_mass_parameter()

        msg_type, topic = OUTPUTS[self._output_type]
        self._output_pub = self.create_publisher(msg_type, topic, 100)
        self._truth_pub = self.create_publisher(
            Float64, 'vibration/ground_truth', GROUND_TRUTH_QOS
        )
        self._clock_pub = self.create_publisher(ClockMsg, '/clock', 10) if self._sim_time else None
        self._msg = msg_type()
        self._msg.header.frame_id = p['frame_id']
        self._set_value = self._message_setter()
        self.commands_received = 0
        self.commands_skipped = 0
        self.create_subscription(Float64, 'position_command', self._on_command, 10)
        self._clock_msg = ClockMsg()
        self._f_true = None
        self._origin_ns = (
            SIM_TIME_ORIGIN_NS if self._sim_time else self.get_clock().now().nanoseconds
        )
        self._wall_start = None  # set by the first tick
        self._publish_truth(self._sim.f_true)
        self._timer = self.create_timer(
            1.0 / TICK_HZ, self._tick, clock=Clock(clock_type=ClockType.STEADY_TIME)
        )
        mode = (
            f'simulated time at {self._speed:g}x, /clock published'
            if self._sim_time
            else 'real time'
        )
        self.get_logger().info(
            f'flexible arm: m = {self._sim.params.tip_mass_kg * 1e3:.2f} g, '
            f'f0 = {self._sim.f_true:.3f} Hz '
            f'(Eq. 23), {self._rate:g} Hz, {mode}, {len(schedule)} move(s), publishing '
            f'{self._output_pub.topic_name} [{self._output_type}]'
        )

    def _message_setter(self):
        """A function writing one measurement into the output message."""
        if self._output_type == WRENCH_STAMPED:
            torque = self._msg.wrench.torque

            def set_torque(value: float) -> None:
                torque.z = value

            return set_torque
        msg = self._msg
        msg.orientation_covariance[0] = -1.0  # sensor_msgs/Imu: not provided
        msg.angular_velocity_covariance[0] = -1.0
        accel = msg.linear_acceleration  # covariance left 0: unknown

        def set_acceleration(value: float) -> None:
            accel.z = value

        return set_acceleration

    @property
    def motor(self) -> Tuple[float, float]:
        """The simulated motor now: (the command it holds theta_m*, its angle theta_m), rad. Not
        published (the node's outputs are the sensor's); what a position_command did."""
        return self._sim.command, self._sim.motor_angle

    def _on_command(self, msg: Float64) -> None:
        """Hold a motor-angle command from the next sample; a non-finite one is skipped, counted
        and warned about."""
        try:
            self._sim.set_command(msg.data)
        except ValueError as err:
            self.commands_skipped += 1
            self.get_logger().warning(
                f'position_command skipped: {err}', throttle_duration_sec=5.0
            )
            return
        if not self.commands_received:
            self.get_logger().info(
                f'position_command {msg.data:g} rad: commands take over from the schedule'
            )
        self.commands_received += 1
        was_waiting = not self._answered
        self._answered = True
        if self._lockstep and was_waiting:
            self._tick()  # the answer came: the next batch now, not at the next tick

    def _lockstep_wait(self) -> bool:
        """In lockstep, whether the next batch must still wait for the commander's answer."""
        if not self._lockstep or not self.commands_received or self._answered:
            return False
        if time.monotonic() - self._clock_at < LOCKSTEP_TIMEOUT:
            return True
        self.lockstep_timeouts += 1
        self.get_logger().warning(
            f'lockstep: no position_command for {LOCKSTEP_TIMEOUT:g} s, going on',
            throttle_duration_sec=5.0,
        )
        return False

    def _samples_until_pause(self) -> int:
        """Samples still to publish before holding at ``pause_at``: up to the first at or after
        it."""
        last = math.ceil(self._pause_at * self._rate - 1e-9)
        return last + 1 - round(self._sim.t * self._rate)

    def _holding(self) -> bool:
        """Whether the arm holds at ``pause_at``; on leaving a hold the wall-clock start moves by
        its length, so the run goes on at ``speed`` instead of catching up (and the lockstep's
        wait for an answer restarts)."""
        if self._pause_at > 0 and self._samples_until_pause() <= 0:
            if self._paused_since is None:
                self._paused_since = time.monotonic()
            return True
        if self._paused_since is not None:
            held = time.monotonic() - self._paused_since
            self._wall_start += held
            self._clock_at += held
            self._paused_since = None
        return False

    # ---- parameters ------------------------------------------------------------------------
    def _validate(self, params: List[Parameter]) -> SetParametersResult:
        """Checks beyond the descriptors' ranges and read-only flags; a refused value is kept out.

        A tip mass is refused when its Eq. 23 frequency would leave fewer than
        :data:`MIN_SAMPLES_PER_PERIOD` samples per period.
        """
        for param in params:
            if param.name == 'pause_at' and param.value > 0 and not self._sim_time:
                return SetParametersResult(successful=False, reason=f'pause_at {NEEDS_SIM_TIME}')
            if param.name == 'tip_mass_kg':
                lo, hi = TIP_MASS_RANGE_KG
                if not lo <= param.value <= hi:  # the schedule's masses have no descriptor
                    return SetParametersResult(
                        successful=False,
                        reason=f'tip_mass_kg {param.value} is outside the '
                        f'physical range [{lo}, {hi}] kg of the arm (45.55 g in Section 5.3)',
                    )
                f0 = natural_frequency_hz(param.value)  # Table 1's bar
                if f0 * MIN_SAMPLES_PER_PERIOD > self._rate:
                    return SetParametersResult(
                        successful=False,
                        reason=f'tip_mass_kg {param.value} gives f0 = {f0:.2f} Hz (Eq. 23), fewer '
                        f'than {MIN_SAMPLES_PER_PERIOD} samples per period at '
                        f'{self._rate:g} Hz',
                    )
        return SetParametersResult(successful=True)

    def _apply(self, params: List[Parameter]) -> None:
        """Apply accepted run-time changes: the tip mass (abruptly, Section 5.5), the noise."""
        for param in params:
            if param.name == 'tip_mass_kg' and param.value != self._sim.params.tip_mass_kg:
                self._sim.set_tip_mass(param.value)
                self.get_logger().info(
                    f'tip mass set to {param.value * 1e3:.2f} g: f0 = {self._sim.f_true:.3f} Hz'
                )
            elif param.name == 'noise_std':
                self._sim.noise_std = float(param.value)
            elif param.name == 'pause_at':
                self._pause_at = float(param.value)

    def _sync_mass_parameter(self) -> None:
        """Show a tip mass set by the schedule in the ``tip_mass_kg`` parameter."""
        mass = self._sim.params.tip_mass_kg
        if self.get_parameter('tip_mass_kg').value != mass:
            self.set_parameters([Parameter('tip_mass_kg', value=mass)])

    # ---- publishing --------------------------------------------------------------------------
    def _publish_truth(self, f: float) -> None:
        if f != self._f_true:
            self._f_true = f
            self._truth_pub.publish(Float64(data=f))

    def _publish_clock(self, ns: int) -> None:
        if self._clock_pub is not None:
            self._clock_msg.clock.sec, self._clock_msg.clock.nanosec = divmod(ns, 1_000_000_000)
            self._clock_pub.publish(self._clock_msg)

    def _tick(self) -> None:
        if self.finished:
            return
        if self._wall_start is None:
            if self._output_pub.get_subscription_count() < self._wait_for_subscribers or (
                self._wait_for_command and not self.commands_received
            ):
                self._publish_clock(self._origin_ns)
                return
            self._wall_start = time.monotonic()
        if self._holding() or self._lockstep_wait():
            return
        due_t = (time.monotonic() - self._wall_start) * self._speed
        if self._duration > 0:
            due_t = min(due_t, self._duration)
        due = int(due_t * self._rate) + 1 - round(self._sim.t * self._rate)
        if self._lockstep:
            due = min(due, max(1, int(LOCKSTEP_BATCH_SECONDS * self._rate)))
        if self._pause_at > 0:
            due = min(due, self._samples_until_pause())
        limit = int(max(MAX_BATCH_SECONDS, BATCH_TICKS * self._speed / TICK_HZ) * self._rate)
        if due > limit:
            self.get_logger().warning(
                f'{due / self._rate:.2f} s of simulated time behind: the machine cannot keep up '
                f'with speed {self._speed:g}',
                throttle_duration_sec=5.0,
            )
            due = limit
        stamp = self._msg.header.stamp
        t = None
        for _ in range(max(due, 0)):
            t, value, f = self._sim.step()
            self._set_value(value)
            ns = self._origin_ns + round(t * 1e9)
            stamp.sec, stamp.nanosec = divmod(ns, 1_000_000_000)
            self._output_pub.publish(self._msg)
            self._publish_truth(f)
        if t is None:
            return
        self._publish_clock(ns)
        self._answered, self._clock_at = False, time.monotonic()
        self._sync_mass_parameter()
        if 0 < self._duration <= self._sim.t:
            self.finished = True
            self.get_logger().info(f'{self._duration:g} s simulated, done')


def main(args=None):
    sys.exit(run(SimNode, args, done=lambda node: node.finished))


if __name__ == '__main__':
    main()
