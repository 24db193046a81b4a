# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""ROS 2 node running the algebraic frequency estimator on one field of a sensor stream.

``ros2 run vib_estimator estimator_node``. A thin shell: it declares the parameters, converts each
message to a ``(stamp, value)`` sample, hands it to :class:`~.stream.EstimatorStream` (the time
base, the estimator -- one :class:`FrequencyEstimator`, or a mode tracker with ``modes`` >= 1 --
and the diagnostics bookkeeping, all without rclpy) and publishes what comes back.

* Input: ``coupling_torque`` (parameter ``input_topic``, read-only) of type ``input_type``
  (read-only; the types and components of :mod:`vib_estimator.io.fields`), best-effort sensor-data
  QoS with a deeper history (:data:`INPUT_DEPTH`), its stamps' cadence watched (:mod:`.cadence`:
  what never reached the node, counted); field ``component``, or with ``components``
  several fields of each message, estimated jointly (free decays or ``excitation`` ambient:
  docs/channels.md); with ``input_topics`` (read-only, two or more topics of ``input_type``, which
  must have a header) the fields of each topic, the topics' samples aligned by header stamp
  within ``sync_tolerance_s`` (:mod:`vib_estimator.io.align`: the first topic is the time base; a
  message lost on one topic costs that joint sample; a stalled topic makes the status WARN and the
  others wait, bounded), channels named ``topic:field``.
* Output, on each estimate and in this order (:class:`Outputs`): ``vibration/frequency``,
  ``vibration/damping_ratio``, ``vibration/frequency_std``, ``vibration/amplitude``
  (std_msgs/Float64), then ``vibration/reset`` (std_msgs/Header: stamp and frame_id of the
  converging sample); with ``modes`` >= 1 these carry mode 1, and each mode k has
  ``vibration/mode<k>/frequency`` and ``vibration/mode<k>/reset``; with several components also
  ``vibration/mode<k>/shape`` (std_msgs/Float64MultiArray, :meth:`Outputs.publish_shape`).
* Services ``~/reset`` (a new segment now) and ``~/self_test`` (:mod:`.self_test`),
  std_srvs/Trigger, with a request history of :data:`SERVICE_DEPTH`: a burst of calls is queued and
  every call answered, in turn; a self-test runs in a thread, once per configuration and rate,
  its calls answered when it is done (under the identifier it takes about a CPU second: the
  executor thread goes on meanwhile).
* ``/diagnostics`` at 1 Hz (steady clock): one status named after the node (:mod:`.health`).
* ``decide_excitation`` (default true): while ``excitation`` is ``free`` (the default), once the
  input looks driven (now, and in part of its last two minutes; from 20 s on), the node sets its
  own ``excitation`` (and ``ambient_window_s``) to what ``vib-estimator analyze`` decides on those
  seconds (:meth:`~.stream.EstimatorStream.decision`: a building under wind, a machine driven
  without rest), with one log line; from an ``ambient`` it set so, to ``auto`` once the input
  looks free again. False keeps the configured excitation and says on ``/diagnostics`` when the
  input looks driven.

Time base: the header stamps (``t`` = stamp - first stamp, as the offline ``vib-estimator
analyze``, so both give the same floats). A zero stamp, and every sample of a type without a header
(``std_msgs/msg/Float64``, ``Float32``), is stamped with the receipt time on the node clock
(``use_sim_time`` applies). Non-finite values, duplicate and out-of-order stamps, gaps and backward
jumps are the core's business (skipped or restarted, and counted); a JointState without the
configured joint is skipped and counted here.
"""

from __future__ import annotations

import importlib
import itertools
import sys
import time
from functools import partial
from typing import NamedTuple, Optional

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rcl_interfaces.msg import SetParametersResult
from rclpy.clock import Clock, ClockType
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from rclpy.time import Time
from std_msgs.msg import Float64, Float64MultiArray, Header, MultiArrayDimension
from std_srvs.srv import Trigger

from ..core.config import EstimatorConfig
from ..core.estimator import MIN_CHANNELS, Estimate
from ..core.shapes import SHAPE_ROWS, phases_deg, signed_amplitudes
from ..errors import StartupError
from ..io.align import StampAligner
from ..io.fields import (
    channels_getter,
    channels_of,
    check_component,
    check_components,
    check_input_type,
    has_header,
    stamp_ns,
    topic_channels,
)
from ..io.heap import fix_allocator, release_memory
from . import health as H
from .baseline_monitor import BaselineMonitor
from .cadence import Cadence, Watchdog
from .mode_shapes import ModeShapesPublisher
from .parameters import (
    config_of,
    config_value,
    declare,
    declare_config,
    declare_input,
    descriptor,
    warn_unused_params_files,
)
from .runner import run
from .stream import (
    WARMUP_BUFFER,
    WARMUP_MESSAGE,
    EstimatorStream,
    check_channels,
)

#: input history: sensor-data QoS (best effort: it matches best-effort and reliable publishers
#: alike) but 5000 deep instead of 5, so that a burst of 5000 messages at full publisher speed, a
#: stall of 10 s at 500 Hz or 1 s at 5 kHz, drops nothing (Fast DDS caps a reader's history at
#: its default max_samples, 5000: a deeper one held no more). Beyond it the oldest are replaced,
#: counted from the stamps as lost_in_queue (.cadence). The cost: up to 5000 messages held
#: (~1 MB of WrenchStamped), and after a long stall the estimates lag by up to that many samples
#: while the node drains them (benchmarks/bench_node.py measures the effect of the depth).
#: A reliable input would have lost none in the queue, but cannot match the best-effort sensor
#: drivers (QoS incompatible) and makes a slow node slow its publisher down.
#: Fast DDS 2.14, its log at Warning, says "HISTORY DEPTH '5000' is inconsistent with
#: max_samples_per_instance '400' ... Effectively using max_samples_per_instance as depth" (its
#: QoS check compares the depth with the default per-instance limit). Not so for a topic without
#: keys (every ROS message here): its reader history sets max_samples_per_instance to max_samples
#: (5000), so the depth is honoured -- a reader that took nothing keeps the newest 5000 of a burst
#: (400 at depth 400); a depth above 5000 would keep the oldest 5000 and drop the newest, not a
#: keep-last history (test/nodes/test_input_history.py; docs/nodes.md#the-input-qos).
INPUT_DEPTH = 5000
#: output history (reliable, keep-last) of the estimate topics: a node that resumes after a stall
#: (SIGSTOP, CPU starvation) publishes its backlog's estimates at once; at depth 10 a reliable
#: subscriber that had not taken them yet lost the oldest (the soak's shaper_node took 782 of
#: 798 estimates). They are few a second: 100 costs nothing.
OUTPUT_DEPTH = 100


def input_qos() -> QoSProfile:
    """The input subscriptions' QoS: sensor-data reliability and durability, keep-last
    :data:`INPUT_DEPTH`."""
    return QoSProfile(
        depth=INPUT_DEPTH,
        reliability=qos_profile_sensor_data.reliability,
        durability=qos_profile_sensor_data.durability,
    )


class Standby(NamedTuple):
    """A subscription the watchdog made beside a silent one: its token, the subscription, the
    messages the silent one had taken then, and how long it had been silent (s)."""

    token: int
    sub: object
    taken: int
    silent_s: float


#: how often the end of a warm-up is looked for, and after how long it is announced, s
WARMUP_POLL = 0.05
WARMUP_NOTICE = 1.0
#: at most this long (s) feeding the samples held during a warm-up in one callback: the rest in
#: the next turns, the diagnostics and services between them (24 000 held samples fed at once
#: kept /diagnostics silent for 5.4 s in a soak on a loaded machine)
DRAIN_SLICE_S = 0.1
#: the diagnostics are published from the data path when the timer's publication is this late
#: (s since the last): the EventsExecutor runs the timer's event after every message event
#: queued before it, and a node behind its input (a backlog after a stall, a starved CPU) once
#: left /diagnostics silent for 2.4-3.2 s in a soak
DIAGNOSTICS_OVERDUE = 1.5 * H.DIAGNOSTICS_PERIOD
#: how often (s) a self-test run is looked at while calls wait for it (their answer's delay)
SELF_TEST_POLL = 0.02
#: request history of the services: a burst of calls queues instead of being dropped (rclpy's
#: default, 10, answered 21 of 100 simultaneous calls)
SERVICE_DEPTH = 1000
#: the ROS parameters that configure the core, one per EstimatorConfig field
CORE_NAMES = frozenset(EstimatorConfig.names())
#: the ROS parameters that choose the fields of the input
FIELD_NAMES = frozenset(('component', 'components'))
#: the node's own choice of excitation (module doc)
DECIDE_DESCRIPTION = (
    "while excitation is free, switch to what the input needs (analyze's decision over its "
    'last 120 s: ambient or auto, and the ambient window) once it looks driven, and '
    'from ambient to auto once it looks free again; false keeps the configured excitation'
)
#: the Float64 outputs of each estimate, in publication order: (topic under vibration/, field)
FLOAT_OUTPUTS = (
    ('frequency', 'frequency_hz'),
    ('damping_ratio', 'damping'),
    ('frequency_std', 'frequency_std_hz'),
    ('amplitude', 'amplitude'),
)
#: health levels as DiagnosticStatus levels
LEVELS = {
    H.OK: DiagnosticStatus.OK,
    H.WARN: DiagnosticStatus.WARN,
    H.ERROR: DiagnosticStatus.ERROR,
    H.STALE: DiagnosticStatus.STALE,
}


def message_class(input_type: str):
    """The rclpy message class of a supported input type's full name."""
    package, _, name = check_input_type(input_type).split('/')
    return getattr(importlib.import_module(f'{package}.msg'), name)


class Outputs:
    """The publishers of the estimates, and the publication of one estimate (see the module
    doc)."""

    def __init__(self, node: Node):
        self._node = node
        self._msg = Float64()
        self._floats = [
            (node.create_publisher(Float64, f'vibration/{topic}', OUTPUT_DEPTH), field)
            for topic, field in FLOAT_OUTPUTS
        ]
        self._reset = node.create_publisher(Header, 'vibration/reset', OUTPUT_DEPTH)
        self._modes = {}  # mode -> (frequency publisher, reset publisher)
        self._shapes = {}  # mode -> shape publisher (several channels)
        self._shape = Float64MultiArray()

    @property
    def frequency_subscribers(self) -> int:
        """Subscriptions matched to ``vibration/frequency`` (their middleware has matched them,
        not merely seen them in the graph: a new subscriber hears the estimates from then)."""
        return self._floats[0][0].get_subscription_count()

    def set_channels(self, channels, modes: int) -> None:
        """The layout of the shapes of ``channels`` (several: publishers of modes 1..``modes``
        made now, those of higher modes destroyed and made again on an estimate, as
        :meth:`set_modes` does; one channel: none)."""
        joint = len(channels) >= MIN_CHANNELS
        keep = modes if joint else 0
        for k in [k for k in self._shapes if k > keep]:
            self._node.destroy_publisher(self._shapes.pop(k))
        if not joint:
            return
        m = len(channels)
        self._shape.layout.dim = [
            MultiArrayDimension(
                label=','.join(SHAPE_ROWS), size=len(SHAPE_ROWS), stride=len(SHAPE_ROWS) * m
            ),
            MultiArrayDimension(label=','.join(channels), size=m, stride=m),
        ]
        for k in range(1, modes + 1):
            self._shape_publisher(k)

    def _shape_publisher(self, k: int):
        if k not in self._shapes:
            self._shapes[k] = self._node.create_publisher(
                Float64MultiArray, f'vibration/mode{k}/shape', OUTPUT_DEPTH
            )
        return self._shapes[k]

    def publish_shape(self, joint: Estimate) -> None:
        """``vibration/mode<k>/shape``: rows ``shape`` (each channel's signed amplitude),
        ``shape_phase_deg`` (its phase) and ``shape_std`` (its uncertainty), one column per
        channel (``layout.dim[0]``: the rows' names, ``dim[1]``: the channels', comma-joined;
        row-major: the amplitudes first)."""
        msg = self._shape
        parts = (signed_amplitudes(joint.shape), phases_deg(joint.shape), joint.shape_std)
        msg.data = [float(v) for part in parts for v in part]
        self._shape_publisher(joint.mode).publish(msg)

    def set_modes(self, modes: int) -> None:
        """Publishers for modes 1..``modes``; those of higher modes are destroyed."""
        for k in [k for k in self._modes if k > modes]:
            for publisher in self._modes.pop(k):
                self._node.destroy_publisher(publisher)
        for k in range(1, modes + 1):
            self._mode(k)

    def _mode(self, k: int):
        if k not in self._modes:
            self._modes[k] = (
                self._node.create_publisher(Float64, f'vibration/mode{k}/frequency', OUTPUT_DEPTH),
                self._node.create_publisher(Header, f'vibration/mode{k}/reset', OUTPUT_DEPTH),
            )
        return self._modes[k]

    def publish(self, estimate, header: Header) -> None:
        """Mode 0 or 1 on the vibration/ topics, then mode k >= 1 on vibration/mode<k>/."""
        msg = self._msg
        if estimate.mode <= 1:
            for publisher, field in self._floats:
                msg.data = getattr(estimate, field)
                publisher.publish(msg)
            self._reset.publish(header)
        if estimate.mode >= 1:
            frequency, reset = self._mode(estimate.mode)
            msg.data = estimate.frequency_hz
            frequency.publish(msg)
            reset.publish(header)


class EstimatorNode(Node):
    """Publishes the natural frequency of the vibration in one field of a sensor stream."""

    def __init__(self, **kwargs):
        fix_allocator()  # freed arrays given back, not kept resident (docs/soak.md)
        super().__init__('estimator_node', **kwargs)
        self._input_type, topics, tolerance = declare_input(self)
        #: the input topics (several: resolved, their channels are named after them)
        self._topics = topics if len(topics) < 2 else tuple(map(self.resolve_topic_name, topics))
        declare_config(self)
        deciding = declare(self, 'decide_excitation', True, descriptor(DECIDE_DESCRIPTION))
        mode_shapes = ModeShapesPublisher.declare(self)
        #: warnings about params files that set nothing for this node (also logged)
        self.params_file_warnings = warn_unused_params_files(self, kwargs.get('cli_args'))
        try:
            self._fields = self._read_fields()
            self._channels = topic_channels(self._topics, self._fields)
            self._value = channels_getter(self._fields, self._input_type)
            self._stream = EstimatorStream(
                config_of(self),
                time.monotonic(),
                background=True,
                channels=self._channels,
                deciding=deciding,
            )
        except ValueError as err:
            raise StartupError(str(err)) from None
        #: several input topics: their samples aligned by stamp (io.align), counted in the
        #: node's counters
        self._aligner = None
        if len(self._topics) > 1:
            self._aligner = StampAligner(
                len(self._topics),
                round(tolerance * 1e9),
                counters=self._stream.health.node_counters,
                jump_ns=round(self._stream.config.max_gap * 1e9),
            )
        self._align_tick: dict = {}
        #: each input topic's stamps' cadence (what never reached the node, counted: .cadence)
        self._cadences = [
            Cadence(self._stream.health.node_counters, round(self._stream.config.max_gap * 1e9))
            for _ in self._topics
        ]
        self._observe = self._cadences[0].observe  # bound once (data path)
        self._feed = self._stream.feed  # bound once (data path)
        self._ready = self._stream.ready
        self._clock = self.get_clock()
        self._outputs = Outputs(self)
        self._outputs.set_modes(self._stream.config.modes)
        self._outputs.set_channels(self._channels, self._stream.config.modes)
        #: with a geometry_file: vibration/mode_shapes, the modes' shapes for RViz
        self._mode_shapes = ModeShapesPublisher.create(self, mode_shapes, self._channels)
        #: health monitoring against a learned baseline (baseline_file; docs/health.md)
        self.baseline_monitor = BaselineMonitor(self, lambda: self._stream.origin)
        # before the subscription: a node whose input is matched answers its services; a deep
        # request history, so that a burst of calls queues instead of being dropped
        service_qos = QoSProfile(depth=SERVICE_DEPTH, reliability=ReliabilityPolicy.RELIABLE)
        self.create_service(Trigger, '~/reset', self._on_reset, qos_profile=service_qos)
        self._create_self_test(service_qos)
        self._create_inputs()
        self.add_on_set_parameters_callback(self._check_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)
        self._create_timers()
        self.get_logger().info(
            f'estimating on {self._input_names} '
            f'({self._input_type} [{", ".join(self._channels)}]) with '
            f'{self._stream.config}'
        )

    def _create_inputs(self) -> None:
        """The input subscriptions (one per topic), their watchdogs and bookkeeping."""
        if self._aligner is None:
            callbacks = [self._on_stamped if has_header(self._input_type) else self._on_unstamped]
        else:
            callbacks = [partial(self._on_topic, i) for i in range(len(self._topics))]
        self._input_qos = input_qos()
        self._input_callbacks = callbacks
        #: per input topic: the token of the subscription whose messages are taken, the messages
        #: taken, and the standby subscription the watchdog made beside a silent one
        self._tokens = itertools.count()
        self._taking = [next(self._tokens) for _ in self._topics]
        self._taken = [0 for _ in self._topics]
        self._standby: list = [None for _ in self._topics]
        self._subscriptions_in = [
            self._subscribe(i, self._taking[i]) for i in range(len(self._topics))
        ]
        #: each input subscription's watchdog (never deaf: .cadence.Watchdog)
        self._watchdogs = [Watchdog() for _ in self._topics]
        self._input_names = ','.join(sub.topic_name for sub in self._subscriptions_in)

    def _create_timers(self) -> None:
        """/diagnostics and the warm-up poll, on the steady clock: diagnostics go on (and can
        say STALE) when sim time stops; while the kernels compile (a first start: see .stream),
        the poll looks for the end of the warm-up."""
        self._diagnostics_pub = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        self._diagnostics_due = time.monotonic() + DIAGNOSTICS_OVERDUE
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.create_timer(H.DIAGNOSTICS_PERIOD, self._publish_diagnostics, clock=steady)
        self._warmup_timer = self.create_timer(WARMUP_POLL, self._poll_warmup, clock=steady)
        self._warmup_logged = False
        #: the parameters being set are the node's own decision (:meth:`_decide`)
        self._deciding = False

    def _create_self_test(self, qos: QoSProfile) -> None:
        """``~/self_test``, answered when its run (a thread: :meth:`.stream.EstimatorStream.
        self_test`) is done, never holding the executor thread: a call that finds it running is
        answered later, by :meth:`_answer_self_tests`. rclpy's executors (the EventsExecutor and
        the single-threaded one) send the callback's response through the service's
        ``send_response(response, header)``; the service's own is replaced by
        :meth:`_send_or_defer`, which keeps such a response and its request's header until then.
        (The Jazzy wheels' EventsExecutor cannot take an ``async`` service callback: a
        ``TypeError`` in ``send_response``, fixed by ros2/rclpy#1613, not in 7.1.6.)"""
        service = self.create_service(Trigger, '~/self_test', self._on_self_test, qos_profile=qos)
        self._send_self_test = service.send_response
        service.send_response = self._send_or_defer
        #: the response a self-test call returned while the run goes on (sent later)
        self._deferred = None
        #: (response, request header) of the calls waiting for the running self-test
        self._self_test_waiting = []
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self._self_test_timer = self.create_timer(
            SELF_TEST_POLL, self._answer_self_tests, clock=steady
        )
        self._self_test_timer.cancel()

    def _subscribe(self, index: int, token: int, lost_events: bool = True):
        """The subscription ``token`` to input topic ``index`` (with ``lost_events``, the
        middleware's own count of the samples it lost before the queue). A subscription the
        watchdog makes has none: rclpy's EventsExecutor dispatches a QoS event of a subscription
        destroyed meanwhile (InvalidHandle, or a segmentation fault; ros2/rclpy#1644) -- re-created
        every 20 ms under sim_node at speed 10 it died in 4 runs of 4 within 4-37 s, without the
        event callback 0 in 2 runs of 2500 re-creations (benchmarks/resubscribe.py;
        docs/nodes.md#never-deaf)."""
        events = SubscriptionEventCallbacks(message_lost=self._on_message_lost)
        return self.create_subscription(
            message_class(self._input_type),
            self._topics[index],
            partial(self._on_input, index, token),
            self._input_qos,
            event_callbacks=events if lost_events else None,
        )

    def _on_input(self, index: int, token: int, msg) -> None:
        """A message of input topic ``index`` from subscription ``token``. The current one's is
        taken. The standby's (:meth:`_watch_inputs`) makes the standby current -- the old one was
        deaf -- unless the old one took a message since the standby was made: its publisher had
        only paused, and the standby's copy is dropped. A message of a subscription destroyed
        meanwhile is dropped."""
        if token != self._taking[index]:
            standby = self._standby[index]
            if standby is None or token != standby.token or self._taken[index] > standby.taken:
                return
            self._standby[index] = None
            self.destroy_subscription(self._subscriptions_in[index])
            self._subscriptions_in[index], self._taking[index] = standby.sub, token
            self.get_logger().warn(
                f'{standby.sub.topic_name}: the input subscription was deaf (nothing taken for '
                f'{standby.silent_s:.1f} s with its publisher(s) matched, which the standby made '
                'beside it now hears): replaced by the standby (counted in input_resubscribed)'
            )
        self._taken[index] += 1
        self._input_callbacks[index](msg)

    def _watch_inputs(self, now: float) -> None:
        """Never deaf: beside an input subscription whose publishers are matched but from which
        nothing was taken for long (:class:`.cadence.Watchdog`), make a standby one, with one INFO
        per silence; the first of the two to take a message is kept (:meth:`_on_input`: a WARN
        when it is the standby, the old one deaf; none for a publisher that paused). Made
        before the old one is destroyed, so a publisher that had only paused (a simulator held, a
        replay paused) loses nothing: a new subscription hears nothing until the publisher has
        discovered it, seconds on a loaded machine (a CI run's demo lost a tip mass's whole
        vibration so)."""
        stamped = has_header(self._input_type)
        for i, watchdog in enumerate(self._watchdogs):
            sub, cadence = self._subscriptions_in[i], self._cadences[i]
            standby = self._standby[i]
            if standby is not None and self._taken[i] > standby.taken:
                self._drop_standby(i)  # the old one hears again: its publisher had paused
            taken_at = cadence.taken_at if stamped else self._stream.health.input_at
            matched = sub.get_publisher_count()
            if not watchdog.check(now, taken_at, matched, cadence.period_s):
                continue
            self._drop_standby(i)  # one made in this silence has heard nothing either
            token = next(self._tokens)
            silent = now - taken_at
            self._standby[i] = Standby(
                token, self._subscribe(i, token, False), self._taken[i], silent
            )
            self._stream.health.count('input_resubscribed')
            if watchdog.episode == 1:  # a publisher paused, or a deaf subscription: not known yet
                self.get_logger().info(
                    f'{sub.topic_name}: {matched} publisher(s) matched but no message taken for '
                    f'{silent:.1f} s: a standby subscription is made beside it, the first of the '
                    'two to take a message kept (counted in input_resubscribed; again, without a '
                    'log, while the silence lasts; a WARN if the standby is the one that hears)'
                )

    def _drop_standby(self, index: int) -> None:
        """Destroy input topic ``index``'s standby subscription, if any."""
        standby, self._standby[index] = self._standby[index], None
        if standby is not None:
            self.destroy_subscription(standby.sub)

    def _read_fields(self):
        """The fields of the current ``component`` / ``components`` (ValueError if bad)."""
        return channels_of(
            self.get_parameter('component').value,
            self.get_parameter('components').value,
            self._input_type,
        )

    # ---- parameters ------------------------------------------------------------------------
    def _check_parameters(self, parameters) -> SetParametersResult:
        """Refuse, with the core's reason, a change that would make an invalid configuration."""
        changes = {p.name: config_value(p.value) for p in parameters if p.name in CORE_NAMES}
        fields = {
            'component': self.get_parameter('component').value,
            'components': self.get_parameter('components').value,
            **{p.name: p.value for p in parameters if p.name in FIELD_NAMES},
        }
        try:
            check_component(fields['component'], self._input_type)
            check_components(fields['components'] or (), self._input_type)
            config = self._stream.config.replace(**changes)
            check_channels(
                topic_channels(self._topics, channels_of(**fields, input_type=self._input_type)),
                config,
            )
        except ValueError as err:
            return SetParametersResult(successful=False, reason=str(err))
        return SetParametersResult(successful=True)

    def _apply_parameters(self, parameters) -> None:
        """Rebuild the estimator after an accepted change: a fresh segment, same time origin."""
        names = {p.name for p in parameters}
        if 'decide_excitation' in names:
            self._stream.deciding = self.get_parameter('decide_excitation').value
        if not names & (CORE_NAMES | FIELD_NAMES):
            return
        fields = self._read_fields()
        if fields == self._fields and config_of(self) == self._stream.config:
            return  # set to the values in force: the estimator goes on (its window kept)
        self._stream.decided = self._deciding  # a change of the user's is the user's
        self._fields = fields
        self._channels = topic_channels(self._topics, self._fields)
        self._value = channels_getter(self._fields, self._input_type)
        if self._aligner is not None:  # the queued samples may carry other fields
            self._aligner.clear()
            self._aligner.jump_ns = round(config_of(self).max_gap * 1e9)
        for cadence in self._cadences:
            cadence.back_ns = round(config_of(self).max_gap * 1e9)
        self._stream.configure(config_of(self), self._channels, prime=self._deciding)
        self._outputs.set_modes(self._stream.config.modes)
        self._outputs.set_channels(self._channels, self._stream.config.modes)
        if self._mode_shapes is not None:
            self._mode_shapes.set_channels(self._channels)
        self._ready = self._stream.ready
        if not self._ready or self._stream.compiling:  # (estimating uncompiled meanwhile)
            self._warmup_logged = False
            self._warmup_timer.reset()
        self.get_logger().info(
            f'parameters {", ".join(sorted(names))} changed: estimator '
            f'restarted on [{", ".join(self._channels)}] with {self._stream.config}'
        )

    # ---- data path -------------------------------------------------------------------------
    def _on_stamped(self, msg) -> None:
        """A message with a header: its stamp is the sample's time."""
        value = self._stamped_value(msg)
        if value is not None:
            stamp = stamp_ns(msg.header)
            if self._observe(stamp, time.monotonic()):
                self._jumped(stamp)
            self._take(stamp, value, msg.header)

    def _stamped_value(self, msg):
        """The channels' value(s) of a message with a header (its zero stamp replaced by the
        receipt time); None, counted, for a JointState without the configured joints."""
        value = self._value(msg)
        if value is None:
            self._skip_joint_missing()
            return None
        header = msg.header
        if header.stamp.sec == 0 and header.stamp.nanosec == 0:
            self._replace_zero_stamp(header)
        return value

    def _take(self, stamp: int, value, header: Header) -> None:
        """One sample: held during a warm-up, else estimated on and its estimates published."""
        if time.monotonic() >= self._diagnostics_due:
            self._publish_diagnostics(timer=False)
        if not self._ready:
            self._hold(stamp, value, header)
            return
        estimates = self._feed(stamp, value)
        if estimates:
            self._publish(estimates, header)

    def _on_unstamped(self, msg) -> None:
        """A message without a header: its receipt time on the node clock is the sample's time
        (read through the clock's handle: a third of the cost of ``Clock.now()``)."""
        handle = self._clock.handle
        with handle:
            now = handle.get_now().nanoseconds
        if time.monotonic() >= self._diagnostics_due:
            self._publish_diagnostics(timer=False)
        if not self._ready:
            self._hold(now, self._value(msg), None)
            return
        estimates = self._feed(now, self._value(msg))
        if estimates:
            self._publish(estimates, Header(stamp=Time(nanoseconds=now).to_msg()))

    def _on_topic(self, index: int, msg) -> None:
        """A message of input topic ``index`` (several ``input_topics``): its values wait in the
        aligner until every topic has a sample of the same stamp (:mod:`..io.align`)."""
        value = self._stamped_value(msg)
        if value is None:
            return
        values = value if isinstance(value, tuple) else (value,)
        stamp = stamp_ns(msg.header)
        if self._cadences[index].observe(stamp, time.monotonic()):
            self._jumped(stamp)
        for stamp, joint, first in self._aligner.push(index, stamp, values, msg.header):
            self._take(stamp, joint, first)

    def _jumped(self, stamp: int) -> None:
        """The stamps jumped forward (:mod:`.cadence`: counted in ``stamp_jumps``, no sample
        counted missing): restart the estimator there, and say so."""
        self._stream.restart()
        self.get_logger().warn(
            f'{self._input_names}: the header stamps jumped forward to '
            f'{stamp * 1e-9:.9f} s, faster than their live rate can account for (a clock set, a '
            'source restarted ahead): the estimator restarts (counted in stamp_jumps)'
        )

    def _on_message_lost(self, info) -> None:
        """The middleware lost samples of an input topic before its queue (counted)."""
        self._stream.health.count('lost_in_transport', info.total_count_change)

    def _publish(self, estimates, header: Header) -> None:
        """Publish the estimates of the sample of ``header`` (see :class:`Outputs`)."""
        for estimate in estimates:
            self._outputs.publish(estimate, header)
            if estimate.shape is not None:  # several channels: the mode's shape too
                self._outputs.publish_shape(estimate)
            if self._mode_shapes is not None:
                self._mode_shapes.update(estimate, estimate.shape)
            if self.baseline_monitor.active:
                self.baseline_monitor.estimate(estimate)
            self._stream.published(estimate, time.monotonic())

    # ---- warm-up (the kernels compile in a thread; see .stream) -------------------------------
    def _hold(self, stamp: int, value: float, header: Optional[Header]) -> None:
        """Keep a sample until the kernels are ready (the first drop is logged once)."""
        if self._stream.hold(stamp, value, header):
            self.get_logger().warn(
                f'{self._input_names}: more than {WARMUP_BUFFER} samples arrived '
                'while the estimator kernels compiled: the oldest are dropped (counted as '
                'dropped_warmup; `vib-estimator warmup` compiles them ahead of a start)'
            )

    def _poll_warmup(self) -> None:
        """At the end of a warm-up: install the estimator, estimate on the held samples (in order,
        :data:`DRAIN_SLICE_S` of them a turn) and say how long it took."""
        uncompiled = self._stream.ready  # estimating uncompiled meanwhile (see .stream)
        try:
            drained = self._stream.poll(DRAIN_SLICE_S)
        except Exception as err:  # a compile that failed: say so, never a silent node
            self._warmup_timer.cancel()
            self.get_logger().error(f'the estimator kernels failed to compile: {err}')
            raise StartupError(f'the estimator kernels failed to compile: {err}') from None
        if drained is None:
            if self._stream.ready and not self._stream.compiling:  # nothing left to wait for
                self._warmup_timer.cancel()
                self._ready = True
                return
            if (
                not self._warmup_logged
                and self._stream.warmup_elapsed(time.monotonic()) > WARMUP_NOTICE
            ):
                self._warmup_logged = True
                meanwhile = (
                    'estimating with them uncompiled meanwhile'
                    if uncompiled
                    else 'samples are held until they are ready'
                )
                self.get_logger().info(
                    f'{WARMUP_MESSAGE}: {meanwhile} (`vib-estimator warmup` compiles them ahead)'
                )
            return
        for header, estimates in drained:
            self._publish(
                estimates,
                header
                if header is not None
                else Header(stamp=Time(nanoseconds=self._stream.origin).to_msg()),
            )
        if not self._stream.ready:  # more held: the next turn goes on
            return
        self._warmup_timer.cancel()
        self._ready = True
        dropped = self._stream.health.node_counters['dropped_warmup']
        seconds = self._stream.warmup_seconds
        meanwhile = (
            'estimated uncompiled meanwhile'
            if uncompiled
            else f'{self._stream.warmup_held} samples held meanwhile, {dropped} dropped'
        )
        self.get_logger().info(f'estimator kernels ready after {seconds:.1f} s ({meanwhile})')

    def _replace_zero_stamp(self, header: Header) -> None:
        """Stamp a message that came without one with its receipt time (node clock)."""
        header.stamp = self._clock.now().to_msg()
        if self._stream.health.count('zero_stamps_replaced') == 1:  # warn once (rclpy's once=True
            # costs ~0.15 ms a call)
            self.get_logger().warn(
                f'{self._input_names}: zero header stamps are '
                'replaced by the receipt time (counted in the diagnostics)'
            )

    def _skip_joint_missing(self) -> None:
        """Count (and the first time, log) a JointState message without the configured joint."""
        if self._stream.health.count('skipped_joint_missing') == 1:
            self.get_logger().warn(
                f'{self._input_names}: messages without the '
                f'joint of [{", ".join(self._channels)}] are skipped (counted in the '
                'diagnostics)'
            )

    # ---- services --------------------------------------------------------------------------
    def _on_reset(self, request, response):
        """``~/reset``: start a new segment at the last sample; counters kept."""
        response.success, response.message = self._stream.reset()
        self.get_logger().info(f'reset requested: {response.message}')
        return response

    def _on_self_test(self, request, response):
        """``~/self_test``: three tones through a fresh estimator of the live configuration (its
        run in a thread: a call that finds it running is answered when it is done)."""
        result = self._stream.self_test(wait=False)
        if result is None:
            self._deferred = response  # kept by _send_or_defer, answered by _answer_self_tests
            if self._self_test_timer.is_canceled():
                self._self_test_timer.reset()
            return response
        return self._self_tested(response, result)

    def _self_tested(self, response, result):
        """``response`` filled with the self-test's ``result``, logged."""
        response.success, response.message = result
        text = 'self test ' + response.message.replace('\n', '; ')
        if response.success:  # one call site per severity (rclpy refuses a change)
            self.get_logger().info(text)
        else:
            self.get_logger().warn(text)
        return response

    def _send_or_defer(self, response, header) -> None:
        """The self-test service's ``send_response``: a response :meth:`_on_self_test` deferred is
        kept with its request's header; any other is sent."""
        if response is self._deferred:
            self._deferred = None
            self._self_test_waiting.append((response, header))
            return
        self._send_self_test(response, header)

    def _answer_self_tests(self) -> None:
        """Every :data:`SELF_TEST_POLL` s while calls wait: once the self-test's run is done,
        answer them all."""
        result = self._stream.self_test(wait=False)
        if result is None:
            return
        self._self_test_timer.cancel()
        waiting, self._self_test_waiting = self._self_test_waiting, []
        for response, header in waiting:
            self._send_self_test(self._self_tested(response, result), header)

    # ---- diagnostics -----------------------------------------------------------------------
    @property
    def pending_aligned(self) -> int:
        """With several ``input_topics``: the samples waiting for the other topics (0 else)."""
        return 0 if self._aligner is None else self._aligner.pending

    @property
    def counters(self):
        """The core counters since start (across parameter changes) and the node's own
        (:data:`~vib_estimator.nodes.health.NODE_COUNTERS`)."""
        return self._stream.counters

    def _decide(self) -> None:
        """Apply the stream's decision (``decide_excitation``), as the node's own parameters."""
        decision = self._stream.decision()
        if decision is None:
            return
        wanted = decision.changes()
        changes = [
            Parameter(name, Parameter.Type.DOUBLE_ARRAY, [float(v) for v in value])
            if isinstance(value, list)  # (an empty list has no type rclpy can infer)
            else Parameter(name, value=value)
            for name, value in wanted.items()
        ]
        config = self._stream.config
        what = f'excitation {config.excitation} -> {decision.excitation}'
        if wanted.get('modes', config.modes) != config.modes:
            what += f', modes {config.modes} -> {decision.modes}'
        self.get_logger().info(
            f'{what}: {decision.reason} (decide_excitation:=false keeps the configured excitation)'
        )
        self._deciding = True
        try:  # at once: one estimator built and primed, not one per parameter (docs/soak.md)
            results = [self.set_parameters_atomically(changes)]
        finally:
            self._deciding = False
        refused = [r.reason for r in results if not r.successful]
        if refused:
            self.get_logger().warn(f'the decided excitation was refused: {"; ".join(refused)}')

    def _publish_diagnostics(self, timer: bool = True) -> None:
        """Publish the status; log the last estimate every 10 s (rclpy's throttled logging costs
        ~0.15 ms a call, too much for the data path). From the 1-s timer, or from the data path
        when the timer's turn is late (``timer`` False: input flows, the watchdog is not asked)."""
        now = time.monotonic()
        self._diagnostics_due = now + DIAGNOSTICS_OVERDUE
        for cadence in self._cadences:
            cadence.flush(now)
            if cadence.gap_pending:  # its samples used span it: no rate this status
                self._stream.health.hold_rate()
        status = self._stream.status(now)
        if timer:
            self._watch_inputs(now)
            if self._stream.trim_due:  # an estimator (re)built since: its freed pages back
                self._stream.trim_due = False
                release_memory()
        if self._aligner is not None:
            counters = self._stream.health.node_counters
            lagging = self._aligner.lagging(round(H.STALE_AFTER * 1e9))
            status = H.alignment_status(
                status,
                [self._subscriptions_in[i].topic_name for i in lagging],
                self.pending_aligned,
                counters,
                self._align_tick,
            )
            self._align_tick = {name: counters[name] for name in H.ALIGN_PROBLEMS}
        if self._stream.deciding:
            self._decide()
        if self.baseline_monitor.active:
            status = self.baseline_monitor.status(status)
        if status.log:
            self.get_logger().warn(status.log)
        status.values['frequency_subscribers'] = self._outputs.frequency_subscribers
        array = DiagnosticArray(
            status=[
                DiagnosticStatus(
                    level=LEVELS[status.level],
                    name=self.get_fully_qualified_name(),
                    message=status.message,
                    hardware_id=self._input_names,
                    values=[
                        KeyValue(key=key, value=H.format_value(value))
                        for key, value in status.values.items()
                    ],
                )
            ]
        )
        array.header.stamp = self._clock.now().to_msg()
        self._diagnostics_pub.publish(array)
        estimate = self._stream.health.last_estimate
        if estimate is not None:
            self.get_logger().info(
                f'{status.message}: last {estimate.frequency_hz:.4f} Hz '
                f'after {estimate.convergence_time:.3f} s',
                throttle_duration_sec=10.0,
            )


def main(args=None):
    """Entry point of ``ros2 run vib_estimator estimator_node``."""
    sys.exit(run(EstimatorNode, args))


if __name__ == '__main__':
    main()
