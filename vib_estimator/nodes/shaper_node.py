# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``shaper_node``: the reference shaped for the estimated vibration, as the position command.

``ros2 run vib_estimator shaper_node``. A thin shell around
:class:`vib_estimator.control.shaping.StreamingShaper`:

* Input: ``reference`` (``std_msgs/Float64``, the unshaped motor-angle reference, rad; held
  between messages), ``vibration/frequency`` (Hz) and ``vibration/damping_ratio`` (NaN from models
  without damping: ignored) from ``estimator_node``.
* Output: ``position_command`` (``std_msgs/Float64``) at ``rate_hz`` on the node clock, from the
  first reference on: the reference sampled at ``rate_hz`` and convolved with the shaper
  ``shaper`` designed for the latest estimate (the median of the last ``median_of``). When several
  samples are due at once (a stalled executor, a simulated clock running fast) they are all
  computed and the last one is published. With ``use_sim_time`` the node ticks on every
  ``/clock`` message, at its time, instead of a timer (so ``sim_node``'s ``lockstep`` gets one
  command per step).
* A new design (new estimate, parameter change) is switched in only while the reference is at
  rest (:class:`StreamingShaper`), so a move is never shaped by two shapers. Until the first
  frequency estimate the reference passes through, or is shaped for ``initial_frequency_hz``;
  until the first damping estimate the design uses the parameter ``damping_ratio``.
* ``/diagnostics`` at 1 Hz (steady clock): the shaper in use, its design and impulses, counters.
"""

from __future__ import annotations

import math
import statistics
import sys
import time
from collections import deque
from typing import List, Optional

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rcl_interfaces.msg import SetParametersResult
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock as ClockMsg
from std_msgs.msg import Float64

from ..control.shaping import MAX_DAMPING, SHAPERS, Shaper, StreamingShaper, design, none
from ..errors import StartupError
from .health import DIAGNOSTICS_PERIOD
from .parameters import declare, descriptor, warn_unused_params_files
from .runner import run

#: the status goes WARN when a new design has waited this long for the reference to rest, s
PENDING_WARN_AFTER = 10.0
#: frequency estimates outside [MIN_FREQUENCY_HZ, rate_hz / 4] are ignored (counted)
MIN_FREQUENCY_HZ = 0.01
#: at most this much simulated or real time is computed in one tick; beyond, the node skips ahead
MAX_CATCH_UP_S = 1.0
#: history of the estimate subscriptions: as deep as estimator_node's estimate publishers
#: (``OUTPUT_DEPTH``), so that a backlog's burst of estimates (the estimator resuming after a
#: stall) is taken whole
ESTIMATE_DEPTH = 100

PARAMETERS = {
    # name: (default, descriptor)
    'shaper': (
        'zvd',
        descriptor(
            f'input shaper, one of {", ".join(SHAPERS)}; a change applies once the reference rests'
        ),
    ),
    'rate_hz': (500.0, descriptor('rate of position_command, Hz', (1.0, 10000.0), read_only=True)),
    'damping_ratio': (
        0.0,
        descriptor(
            'damping ratio the shaper is designed for until a vibration/damping_ratio estimate '
            'arrives',
            (0.0, MAX_DAMPING),
        ),
    ),
    'initial_frequency_hz': (
        0.0,
        descriptor(
            'design frequency before the first estimate, Hz; 0 = pass the reference through '
            'until then',
            (0.0, 1000.0),
        ),
    ),
    'median_of': (
        1,
        descriptor(
            'design for the median of the last median_of estimates (1 = the latest)', (1, 50)
        ),
    ),
    'rest_tolerance': (
        1e-6,
        descriptor(
            'the reference is at rest while it stays within this of one value, rad', (0.0, 1.0)
        ),
    ),
}


class ShaperNode(Node):
    """Publishes ``position_command``: ``reference`` shaped for the estimated vibration."""

    def __init__(self, **kwargs):
        super().__init__('shaper_node', **kwargs)
        p = {
            name: declare(self, name, default, desc)
            for name, (default, desc) in PARAMETERS.items()
        }
        warn_unused_params_files(self, kwargs.get('cli_args'))
        self._rate = p['rate_hz']
        self._check_parameters(
            [Parameter(name, value=value) for name, value in p.items()], startup=True
        )
        self._frequencies: deque = deque(maxlen=p['median_of'])
        self._dampings: deque = deque(maxlen=p['median_of'])
        self._shaper = StreamingShaper(none(), self._rate, p['rest_tolerance'])
        self.counters = dict.fromkeys(
            (
                'references',
                'references_skipped',
                'frequency_estimates',
                'damping_estimates',
                'estimates_ignored',
                'design_failures',
                'commands_published',
            ),
            0,
        )
        self._reference: Optional[float] = None
        self._t0_ns: Optional[int] = None  # clock at the first reference
        self._k = 0  # samples computed since t0
        self._pending_since: Optional[float] = None
        #: estimates ignored since the last one taken, and what the last ignored one was
        self._ignored_run = 0
        self._ignored_last = ''
        self._command = Float64()
        self._command_pub = self.create_publisher(Float64, 'position_command', 10)
        self._diagnostics_pub = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        self.create_subscription(Float64, 'reference', self._on_reference, 10)
        self._frequency_sub = self.create_subscription(
            Float64, 'vibration/frequency', self._on_frequency, ESTIMATE_DEPTH
        )
        self.create_subscription(
            Float64, 'vibration/damping_ratio', self._on_damping, ESTIMATE_DEPTH
        )
        self.add_on_set_parameters_callback(self._check_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)
        self._redesign()
        if self.get_parameter('use_sim_time').value:
            # tick on every /clock, at its time: a lockstep simulator gets one answer per step
            self.create_subscription(ClockMsg, '/clock', self._on_clock, 10)
        else:
            self.create_timer(
                1.0 / self._rate, lambda: self._tick(self.get_clock().now().nanoseconds)
            )
        self.create_timer(
            DIAGNOSTICS_PERIOD,
            self._publish_diagnostics,
            clock=Clock(clock_type=ClockType.STEADY_TIME),
        )
        self.get_logger().info(
            f'shaping {self.resolve_topic_name("reference")} into '
            f'{self._command_pub.topic_name} at {self._rate:g} Hz with '
            f'{p["shaper"]}'
        )

    # ---- parameters ------------------------------------------------------------------------
    def _check_parameters(
        self, params: List[Parameter], startup: bool = False
    ) -> SetParametersResult:
        """Refuse an unknown shaper name (ranges and read-only are the descriptors' business);
        at start-up a refusal raises StartupError."""
        for param in params:
            if param.name == 'shaper' and param.value not in SHAPERS:
                reason = f'shaper must be one of {", ".join(SHAPERS)}, got {param.value!r}'
                if startup:
                    raise StartupError(reason)
                return SetParametersResult(successful=False, reason=reason)
        return SetParametersResult(successful=True)

    def _apply_parameters(self, params: List[Parameter]) -> None:
        names = {p.name for p in params}
        if 'median_of' in names:
            n = self.get_parameter('median_of').value
            self._frequencies = deque(self._frequencies, maxlen=n)
            self._dampings = deque(self._dampings, maxlen=n)
        if 'rest_tolerance' in names:
            self._shaper.rest_tolerance = float(self.get_parameter('rest_tolerance').value)
        if names & {'shaper', 'damping_ratio', 'initial_frequency_hz', 'median_of'}:
            self._redesign()

    # ---- design ----------------------------------------------------------------------------
    def design_mode(self):
        """(frequency Hz or None, damping ratio, where the damping comes from) to design for."""
        if self._frequencies:
            f = statistics.median(self._frequencies)
        else:
            f = self.get_parameter('initial_frequency_hz').value or None
        if self._dampings:
            return f, statistics.median(self._dampings), 'estimate'
        return f, self.get_parameter('damping_ratio').value, 'parameter'

    def _redesign(self) -> None:
        """Ask the streaming shaper for the design of the current estimate (applied at rest)."""
        f, zeta, _ = self.design_mode()
        name = self.get_parameter('shaper').value
        try:
            shaper = none() if f is None or name == 'none' else design(name, f, zeta)
        except ValueError as err:
            self.counters['design_failures'] += 1
            self.get_logger().warning(
                f'{name} for {f} Hz, zeta {zeta}: {err}; keeping {self._shaper.shaper.name}',
                throttle_duration_sec=5.0,
            )
            return
        if not _same(shaper, self._shaper.pending or self._shaper.shaper):
            self._shaper.request(shaper)
            self._pending_since = self._pending_since or time.monotonic()

    # ---- inputs ----------------------------------------------------------------------------
    def _on_reference(self, msg: Float64) -> None:
        if not math.isfinite(msg.data):
            self.counters['references_skipped'] += 1
            self.get_logger().warning(
                f'non-finite reference {msg.data} skipped', throttle_duration_sec=5.0
            )
            return
        self.counters['references'] += 1
        self._reference = msg.data
        if self._t0_ns is None:
            self._t0_ns = self.get_clock().now().nanoseconds

    def _on_frequency(self, msg: Float64) -> None:
        self._take_estimate(
            msg.data,
            MIN_FREQUENCY_HZ,
            self._rate / 4,
            'frequency_estimates',
            self._frequencies,
            'frequency',
            'Hz',
        )

    def _on_damping(self, msg: Float64) -> None:
        if not math.isnan(msg.data):  # NaN: a model without damping
            self._take_estimate(
                msg.data,
                0.0,
                MAX_DAMPING,
                'damping_estimates',
                self._dampings,
                'damping ratio',
                '',
            )

    def _take_estimate(
        self, value: float, lo: float, hi: float, counter: str, store: deque, what: str, unit: str
    ) -> None:
        """Keep an estimate within [lo, hi] and redesign; count one outside (or NaN) ignored,
        with a throttled warning (the diagnostics go WARN until an estimate is taken again)."""
        if not lo <= value <= hi:
            self.counters['estimates_ignored'] += 1
            self._ignored_run += 1
            self._ignored_last = (
                f'{what} {value:g}{" " + unit if unit else ""} outside [{lo:g}, {hi:g}]'
            )
            self.get_logger().warning(
                f'ignored {self._ignored_last} ({self._ignored_run} since the last usable '
                f'estimate); keeping {self._shaper.shaper.describe()}: check what publishes '
                f'{self.resolve_topic_name("vibration/frequency")}',
                throttle_duration_sec=5.0,
            )
            return
        self._ignored_run = 0
        self.counters[counter] += 1
        store.append(value)
        self._redesign()

    # ---- output ----------------------------------------------------------------------------
    def _on_clock(self, msg: ClockMsg) -> None:
        self._tick(msg.clock.sec * 1_000_000_000 + msg.clock.nanosec)

    def _tick(self, now: int) -> None:
        """Compute the samples due by ``now`` (ns; sample k at t0 + k / rate_hz on the node
        clock) and publish the last one."""
        if self._reference is None:
            return
        due = math.floor((now - self._t0_ns) * 1e-9 * self._rate)
        if due < self._k - 1 or due - self._k > MAX_CATCH_UP_S * self._rate:
            self._k = due  # the clock jumped (restarted sim, long stall): skip
        for _ in range(due - self._k + 1):
            before = self._shaper.shaper
            self._command.data = self._shaper.update(self._reference)
            if self._shaper.shaper is not before:
                self._log_switch(before)
        self._k = max(self._k, due + 1)
        self._command_pub.publish(self._command)
        self.counters['commands_published'] += 1

    def _log_switch(self, before: Shaper) -> None:
        """Log a new design: at info level when the shaper's kind changed, else at debug."""
        self._pending_since = None
        log = self.get_logger()
        (log.info if self._shaper.shaper.name != before.name else log.debug)(
            f'reference at rest: shaper now {self._shaper.shaper.describe()}'
        )

    # ---- diagnostics -----------------------------------------------------------------------
    def status(self) -> DiagnosticStatus:
        """OK while shaping (or passing through before the first estimate); WARN while the
        estimates received since the last usable one were all ignored (NaN, out of range), or
        when a new design has waited more than PENDING_WARN_AFTER s for the reference to rest."""
        s = self._shaper.shaper
        f, zeta, source = self.design_mode()
        pending = self._shaper.pending
        waited = time.monotonic() - self._pending_since if pending is not None else 0.0
        publishers = self._frequency_sub.get_publisher_count()  # matched, not merely in the graph
        if self._ignored_run:
            level, message = (
                DiagnosticStatus.WARN,
                (
                    f'{self._ignored_run} estimates ignored since the last usable one (last: '
                    f'{self._ignored_last}); in use: {s.describe()}'
                ),
            )
        elif waited > PENDING_WARN_AFTER:
            level, message = (
                DiagnosticStatus.WARN,
                (
                    f'{pending.name} waits {waited:.0f} s for the reference to rest; in use: '
                    f'{s.describe()}'
                ),
            )
        elif s.name == 'none' and f is None:
            level, message = DiagnosticStatus.OK, 'passing through: no frequency estimate yet'
            if not publishers:
                message += f' (no publisher of {self._frequency_sub.topic_name} matched)'
        else:
            level, message = DiagnosticStatus.OK, s.describe()
        values = {
            'shaper': s.name,
            'design_frequency_hz': _format(s.frequency_hz),
            'design_damping_ratio': _format(s.damping),
            'delay_s': _format(s.duration),
            'impulse_times_s': ' '.join(_format(t) for t in s.times),
            'impulse_amplitudes': ' '.join(_format(a) for a in s.amplitudes),
            'pending_shaper': pending.describe() if pending is not None else '',
            'estimate_frequency_hz': _format(f if f is not None else math.nan),
            'estimate_damping_ratio': _format(zeta),
            'damping_source': source,
            'reference_at_rest': str(self._shaper.at_rest).lower(),
            'retunes': str(self._shaper.retunes),
            'estimate_publishers': str(publishers),
            **{name: str(n) for name, n in self.counters.items()},
        }
        return DiagnosticStatus(
            level=level,
            name=self.get_fully_qualified_name(),
            message=message,
            hardware_id=self._command_pub.topic_name,
            values=[KeyValue(key=k, value=v) for k, v in values.items()],
        )

    def _publish_diagnostics(self) -> None:
        array = DiagnosticArray(status=[self.status()])
        array.header.stamp = self.get_clock().now().to_msg()
        self._diagnostics_pub.publish(array)


def _same(a: Shaper, b: Shaper) -> bool:
    return (
        a.name == b.name
        and len(a.times) == len(b.times)
        and all(a.times == b.times)
        and all(a.amplitudes == b.amplitudes)
    )


def _format(value: float) -> str:
    return f'{value:.9g}'


def main(args=None):
    """Entry point of ``ros2 run vib_estimator shaper_node``."""
    sys.exit(run(ShaperNode, args))


if __name__ == '__main__':
    main()
