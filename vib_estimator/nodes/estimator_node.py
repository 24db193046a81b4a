"""ROS 2 node running the algebraic frequency estimator on a ``WrenchStamped`` stream.

``ros2 run vib_estimator estimator_node``. A thin shell around :class:`FrequencyEstimator`: it
declares the parameters, converts each message to a ``(t, y)`` sample, calls the core and publishes.

* Input: ``coupling_torque`` (parameter ``input_topic``, read-only), geometry_msgs/WrenchStamped,
  best-effort sensor-data QoS with a deeper history (:data:`INPUT_DEPTH`); field ``component``.
* Output, on each convergence and in this order: ``vibration/frequency`` (std_msgs/Float64, Hz),
  then ``vibration/reset`` (std_msgs/Header: stamp and frame_id of the converging sample).
* ``/diagnostics`` at 1 Hz (steady clock): one status named after the node (see :meth:`_status`).

Time base: the header stamps, as ``seconds_since(stamp_ns(header), origin)`` with ``origin`` the
first stamp received, exactly as the offline ``vib-estimator analyze``, so both give the same
floats. A zero stamp is replaced by the receipt time on the node clock (``use_sim_time`` applies),
warned once and counted. Non-finite values, duplicate and out-of-order stamps, gaps and backward
jumps are the core's business (skipped or restarted, and counted).
"""
from __future__ import annotations

import math
import sys
import time

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import WrenchStamped
from rcl_interfaces.msg import SetParametersResult
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, qos_profile_sensor_data
from std_msgs.msg import Float64, Header

from ..core import COUNTER_NAMES, EstimatorConfig, FrequencyEstimator
from .runner import StartupError, run
from .parameters import declare, descriptor
from ..io.fields import COMPONENTS, check_component, component_getter, seconds_since, stamp_ns

#: input history: sensor-data QoS (best effort) but 1000 deep instead of 5, so that a scheduling
#: hiccup of up to 2 s at 500 Hz, or a player's burst after a stall, drops nothing
#: (benchmarks/bench_node.py measures the effect of the depth)
INPUT_DEPTH = 1000
#: period of /diagnostics, s
DIAGNOSTICS_PERIOD = 1.0
#: the status goes STALE when no input arrived for this long, s
STALE_AFTER = 2.0
#: core counters that grow when the quality gate holds a converged estimate back, or none forms
HELD_BACK = ('rejected_at_rest', 'rejected_fit', 'rejected_nyquist', 'rejected_damping',
             'max_window_resets')

#: the ROS parameters that configure the core, one per EstimatorConfig field
CORE_NAMES = frozenset(EstimatorConfig.names())


def _config_value(value):
    """A ROS parameter value as EstimatorConfig takes it: an empty array (or none) is None."""
    if value is None or (not isinstance(value, str) and hasattr(value, '__len__')
                         and len(value) == 0):
        return None
    return value


def _format(value) -> str:
    """A diagnostics value: integers exactly, floats to 9 significant digits."""
    return str(value) if isinstance(value, int) else f'{value:.9g}'


class EstimatorNode(Node):
    """Publishes the natural frequency of the vibration in one component of a wrench stream."""

    def __init__(self, **kwargs):
        super().__init__('estimator_node', **kwargs)
        topic = declare(self, 'input_topic', 'coupling_torque', descriptor(
            'input topic, geometry_msgs/msg/WrenchStamped', read_only=True))
        self._component = declare(self, 'component', 'torque.z', descriptor(
            f'field of the wrench to estimate on, one of {", ".join(COMPONENTS)}'))
        self._declare_core_parameters()
        try:
            self._value = component_getter(self._component)
            config = self._config_from_parameters()
        except ValueError as err:
            raise StartupError(str(err)) from None
        self._estimator = FrequencyEstimator(config)
        self._counter_base = dict.fromkeys(COUNTER_NAMES, 0)  # of the estimators replaced
        self._origin = None          # first stamp received, ns: t = 0
        self._zero_stamps = 0
        self._last_estimate = None   # (Estimate, monotonic time published)
        self._held_at_estimate = dict.fromkeys(HELD_BACK, 0)  # HELD_BACK counters then
        self._frequency = Float64()
        self._frequency_pub = self.create_publisher(Float64, 'vibration/frequency', 10)
        self._reset_pub = self.create_publisher(Header, 'vibration/reset', 10)
        self._diagnostics_pub = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        qos = QoSProfile(depth=INPUT_DEPTH, reliability=qos_profile_sensor_data.reliability,
                         durability=qos_profile_sensor_data.durability)
        self._subscription = self.create_subscription(WrenchStamped, topic, self._on_wrench,
                                                      qos)
        self.add_on_set_parameters_callback(self._check_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)
        # diagnostics state at the previous tick
        self._tick_at = time.monotonic()
        self._tick_received = 0
        self._input_at = None
        # on the steady clock: diagnostics go on (and can say STALE) when sim time stops
        self.create_timer(DIAGNOSTICS_PERIOD, self._publish_diagnostics,
                          clock=Clock(clock_type=ClockType.STEADY_TIME))
        self.get_logger().info(f'estimating on {self._subscription.topic_name} '
                               f'[{self._component}] with {config}')

    # ---- parameters ------------------------------------------------------------------------
    def _declare_core_parameters(self) -> None:
        """Declare one parameter per EstimatorConfig field, typed by its default."""
        defaults = EstimatorConfig()
        for name in EstimatorConfig.names():
            description, bounds = EstimatorConfig.describe(name)
            default = getattr(defaults, name)
            if default is None:
                # an optional array, off by default: rclpy cannot infer a type from [], so
                # declare the type and store an empty array unless an override set a value
                declare(self, name, Parameter.Type.DOUBLE_ARRAY,
                        descriptor(description + ' ([] = off)'))
                if self.get_parameter_or(name).type_ == Parameter.Type.NOT_SET:
                    self.set_parameters([Parameter(name, Parameter.Type.DOUBLE_ARRAY, [])])
            else:
                declare(self, name, default, descriptor(description, bounds))

    def _config_from_parameters(self) -> EstimatorConfig:
        """The EstimatorConfig of the current parameter values (raises ValueError if invalid)."""
        return EstimatorConfig().replace(**{
            name: _config_value(self.get_parameter(name).value)
            for name in EstimatorConfig.names()})

    def _check_parameters(self, parameters) -> SetParametersResult:
        """Refuse, with the core's reason, a change that would make an invalid configuration."""
        changes = {p.name: _config_value(p.value) for p in parameters
                   if p.name in CORE_NAMES}
        try:
            for p in parameters:
                if p.name == 'component':
                    check_component(p.value)
            self._estimator.config.replace(**changes)
        except ValueError as err:
            return SetParametersResult(successful=False, reason=str(err))
        return SetParametersResult(successful=True)

    def _apply_parameters(self, parameters) -> None:
        """Rebuild the estimator after an accepted change: a fresh segment, same time origin."""
        names = {p.name for p in parameters}
        if not names & (CORE_NAMES | {'component'}):
            return
        for name, value in self._estimator.counters.items():
            self._counter_base[name] += value
        self._component = self.get_parameter('component').value
        self._value = component_getter(self._component)
        self._estimator = FrequencyEstimator(self._config_from_parameters())
        self.get_logger().info(f'parameters {", ".join(sorted(names))} changed: estimator '
                               f'restarted on [{self._component}] with {self._estimator.config}')

    # ---- data path -------------------------------------------------------------------------
    def _on_wrench(self, msg: WrenchStamped) -> None:
        """Feed one sample to the core; publish frequency then reset when it converges."""
        header = msg.header
        if header.stamp.sec == 0 and header.stamp.nanosec == 0:
            self._replace_zero_stamp(header)
        stamp = stamp_ns(header)
        if self._origin is None:
            self._origin = stamp
        estimate = self._estimator.update(seconds_since(stamp, self._origin),
                                          self._value(msg))
        if estimate is not None:
            self._frequency.data = estimate.frequency_hz
            self._frequency_pub.publish(self._frequency)
            self._reset_pub.publish(header)
            self._last_estimate = (estimate, time.monotonic())
            counters = self.counters
            self._held_at_estimate = {name: counters[name] for name in HELD_BACK}

    def _replace_zero_stamp(self, header: Header) -> None:
        """Stamp a message that came without one with its receipt time (node clock)."""
        header.stamp = self.get_clock().now().to_msg()
        self._zero_stamps += 1
        if self._zero_stamps == 1:   # warn once (rclpy's once=True costs ~0.15 ms a call)
            self.get_logger().warn(f'{self._subscription.topic_name}: zero header stamps are '
                                   'replaced by the receipt time (counted in the diagnostics)')

    # ---- diagnostics -----------------------------------------------------------------------
    @property
    def counters(self):
        """The core counters since start (across parameter changes) and ``zero_stamps_replaced``."""
        totals = {name: self._counter_base[name] + value
                  for name, value in self._estimator.counters.items()}
        totals['zero_stamps_replaced'] = self._zero_stamps
        return totals

    def _status(self) -> DiagnosticStatus:
        """The node's status: STALE without input for STALE_AFTER s; WARN when a HELD_BACK
        counter grew since the last estimate published (the quality gate rejected a converged
        segment, or none converged within max_window); OK otherwise."""
        now = time.monotonic()
        counters = self.counters
        if counters['received'] > self._tick_received:
            self._input_at = now
        held = {name: counters[name] - self._held_at_estimate[name] for name in HELD_BACK}
        if self._input_at is None or now - self._input_at > STALE_AFTER:
            level, message = DiagnosticStatus.STALE, 'no input'
        elif any(held.values()):
            level, message = DiagnosticStatus.WARN, 'held back since the last estimate: ' + \
                ', '.join(f'{name} {n}' for name, n in held.items() if n)
        elif self._last_estimate is None:
            level, message = DiagnosticStatus.OK, 'waiting for a first estimate'
        else:
            level, message = DiagnosticStatus.OK, 'estimating'
        estimate, published_at = self._last_estimate or (None, None)
        values = {
            'last_frequency_hz': estimate.frequency_hz if estimate else math.nan,
            'last_convergence_time_s': estimate.convergence_time if estimate else math.nan,
            'last_damping_ratio': estimate.damping if estimate else math.nan,
            'last_estimate_age_s': now - published_at if estimate else math.nan,
            'input_rate_hz': (counters['received'] - self._tick_received) / (now - self._tick_at),
            **counters,
        }
        self._tick_at, self._tick_received = now, counters['received']
        return DiagnosticStatus(level=level, name=self.get_fully_qualified_name(),
                                message=message, hardware_id=self._subscription.topic_name,
                                values=[KeyValue(key=key, value=_format(value))
                                        for key, value in values.items()])

    def _publish_diagnostics(self) -> None:
        """Publish the status; log the last estimate every 10 s (rclpy's throttled logging costs
        ~0.15 ms a call, too much for the data path)."""
        status = self._status()
        array = DiagnosticArray(status=[status])
        array.header.stamp = self.get_clock().now().to_msg()
        self._diagnostics_pub.publish(array)
        if self._last_estimate is not None:
            estimate = self._last_estimate[0]
            self.get_logger().info(f'{status.message}: last {estimate.frequency_hz:.4f} Hz '
                                   f'after {estimate.convergence_time:.3f} s',
                                   throttle_duration_sec=10.0)


def main(args=None):
    """Entry point of ``ros2 run vib_estimator estimator_node``."""
    sys.exit(run(EstimatorNode, args))


if __name__ == '__main__':
    main()
