# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``bag_replayer``: play a rosbag2 bag (MCAP or sqlite3) or a bare ``.mcap``/``.db3`` file.

A stand-in for ``ros2 bag play`` where only rclpy is installed; its parameters carry the names of
``ros2 bag play``'s options. The recorded CDR bytes are published as they are (header stamps
untouched), each on a publisher of its recorded type, in log-time order across the files of a
split bag and with the recorded spacing of log times divided by ``rate``. Bags written by rosbag2
itself play completely (see :class:`vib_estimator.io.bags.BagReader` for what it works around).

Types. A topic whose message type is not installed is skipped, with one warning naming every such
topic; only a bag with nothing else to play is refused. Types written ``pkg/Name`` (older bags)
are read as ``pkg/msg/Name``.

Scheduling lives in :mod:`vib_estimator.nodes.playback` (no ROS): a timer every :data:`TICK` s
publishes every message whose due time has passed, so the timing error is at most one tick and high
message rates (or rates x100) do not need one timer event per message.

Start. Before the first message the replayer waits until every played topic (with messages) has at
least one matched subscription -- or, once one of them has, :data:`~.playback.SETTLE_S` more for
the others (a topic nobody subscribes to, say ``/vibration/ground_truth``, does not hold back the
ones someone does), or ``wait_timeout`` s since it started with no subscriber at all -- then it
plays, and names the topics still without one. Cross-process discovery takes a second or two, so
without this a consumer started first would miss the start of the bag. ``wait_timeout: 0`` plays at
once; ``delay`` is a minimum wait on top.

QoS. Each publisher offers what the bag recorded as offered for its topic (reliable unless every
recorded publisher was best effort; transient-local only if every one was), keep-last 1000 deep;
without a recorded profile, reliable depth 1000. A best-effort subscriber (sensor-data QoS, like
the estimator node's) matches a reliable publisher.

Parameters:
    bag (string, required): the bag directory or ``.mcap``/``.db3`` file.
    rate (double, 1.0, settable at run time): playback speed factor, > 0.
    loop (bool, false): start over at the end instead of exiting.
    start_offset (double, 0): seconds of the bag to skip from its start.
    topics (string[], all): topics to play.
    remap (string[]): ``old:=new`` renames of bag topics.
    clock_hz (double, 0): publish ``/clock`` (the playback time) at this rate when > 0, for nodes
        with ``use_sim_time``.
    delay (double, 0): seconds to wait before playing.
    wait_timeout (double, 5): seconds to wait at most for subscribers before playing; 0 = none.
    start_paused (bool, false): start paused (see the services).
    strict (bool, false): refuse a bag with a damaged record (checked before playing) instead of
        skipping it.

Damaged records (an MCAP chunk whose CRC-32 or size does not match, an index entry that points at
no message, a payload that does not decode as its type): skipped and counted; the first gives one
WARN naming it, the end-of-bag line says how many were skipped, and the exit code stays 0. With
``strict`` the whole bag is read once before playing and a damaged record is one ``error:`` line
and exit code 2.

Looping waits one mean message spacing of the bag (1 s for a one-message bag) between the last
message and the first one again, and logs "looping" at most every 10 s.

Services (``std_srvs/srv/Trigger``):
    ~/pause: pause playback (and ``/clock``). ~/resume: resume it.
    ~/play_next: while paused, publish the next message at once.

Exits 0 at the end of the bag (unless looping); a bag that cannot be played (missing, corrupt,
truncated, empty, no ``metadata.yaml``, unknown topic, no topic of an installed type) gives one
line on stderr and exit code 2.
"""

from __future__ import annotations

import math
import time
from typing import Dict, List

from builtin_interfaces.msg import Time
from rcl_interfaces.msg import SetParametersResult
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rosbags.interfaces import QosDurability, QosReliability
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Trigger

from ..errors import BagError, EmptyPlayback, StartupError
from ..io.bags import BagReader, TopicInfo
from .bag_recorder import adapted_qos, message_class
from .parameters import declare, descriptor
from .playback import Playback, StartGate
from .runner import run

TICK = 0.001  # s, period of the scheduling timer
DEPTH = 1000  # history depth of the publishers
ACK_TIMEOUT = 2.0  # s to wait at the end for reliable subscribers to acknowledge everything
LOOP_GAP_ONE_MESSAGE = 1.0  # s of bag time between passes of a one-message bag
LOOP_LOG_PERIOD = 10.0  # s, the "looping" line at most this often
#: ranges of the time parameters: start_offset (s; 1e9 s = 31 years, far inside int64 ns), the
#: /clock rate (Hz; above 1 kHz a timer cannot keep up) and delay / wait_timeout (s; a day)
MAX_SECONDS = 1e9
MAX_CLOCK_HZ = 1000.0
MAX_WAIT_S = 86400.0


def offered_policies(info: TopicInfo):
    """(reliability, durability) rclpy policies of each QoS profile recorded for a bag topic."""
    return [
        (
            ReliabilityPolicy.BEST_EFFORT
            if q.reliability == QosReliability.BEST_EFFORT
            else ReliabilityPolicy.RELIABLE,
            DurabilityPolicy.TRANSIENT_LOCAL
            if q.durability == QosDurability.TRANSIENT_LOCAL
            else DurabilityPolicy.VOLATILE,
        )
        for q in info.offered_qos
    ]


def parse_remaps(remap: List[str], bag: BagReader) -> Dict[str, str]:
    """``['old:=new', ...]`` -> ``{old: new}``; ``StartupError`` for a bad rule or unknown
    topic."""
    rules = {}
    for rule in remap:
        old, sep, new = rule.partition(':=')
        if not (sep and old and new):
            raise StartupError(f'parameter remap: {rule!r} is not of the form old:=new')
        bag.topic(old)  # BagError listing the bag's topics if unknown
        rules[old] = new
    return rules


def playable(bag: BagReader, topics: List[str]):
    """``({topic: message class}, ['topic (type)', ...])``: the topics among ``topics`` whose type
    is installed, and the others."""
    classes, skipped = {}, []
    for topic in topics:
        try:
            classes[topic] = message_class(bag.topics[topic].msgtype)
        except ImportError:
            skipped.append(f'{topic} ({bag.topics[topic].msgtype})')
    return classes, skipped


class BagReplayer(Node):
    """Plays the bag of parameter ``bag``; see the module docstring."""

    def __init__(self, **kwargs) -> None:
        super().__init__('bag_replayer', **kwargs)
        settings = self._declare_parameters()
        try:
            self._bag = BagReader(settings['bag'], strict=settings['strict'])
        except BagError as err:
            raise StartupError(str(err)) from None
        #: number of messages published (all loops)
        self.published = 0
        #: set at the end of the bag when not looping; :func:`main` then exits with ``exit_code``
        self.finished = False
        self.exit_code = 0
        try:
            names = self._create_publishers(settings)
            first_ns = self._bag.start_ns + int(round(settings['start_offset'] * 1e9))
            if settings['strict']:
                self._check_records(first_ns)
            self._playback = Playback(
                lambda: self._bag.messages(list(self._outputs), start_ns=first_ns),
                first_ns,
                self.rate,
                settings['loop'],
                settings['start_paused'],
                self._loop_gap_ns(),
            )
        except EmptyPlayback:
            self._bag.close()
            raise StartupError(
                f'bag {self._bag.path} has no message to play after start_offset'
            ) from None
        except (BagError, StartupError) as err:
            self._bag.close()
            raise StartupError(str(err)) from None
        #: damaged records already reported (one WARN, at the first)
        self._warned_damage = False
        self._gate = StartGate(time.monotonic_ns(), settings['delay'], settings['wait_timeout'])
        self._create_timers_and_services(settings['clock_hz'])
        self.get_logger().info(
            f'playing {settings["bag"]}: {", ".join(names)} at rate '
            f'{self.rate}' + (', paused' if settings['start_paused'] else '')
        )

    def _declare_parameters(self) -> dict:
        def param(name, default, description, read_only=True, bounds=None):
            return declare(self, name, default, descriptor(description, bounds, read_only))

        settings = {
            'bag': param('bag', '', 'bag directory, or .mcap / .db3 file, to play'),
            'loop': param('loop', False, 'start over at the end of the bag'),
            'start_offset': param(
                'start_offset',
                0.0,
                'seconds of the bag to skip from its start',
                bounds=(0.0, MAX_SECONDS),
            ),
            'topics': param('topics', Parameter.Type.STRING_ARRAY, 'topics to play (default: all)')
            or [],
            'remap': param('remap', Parameter.Type.STRING_ARRAY, 'old:=new topic renames') or [],
            'clock_hz': param(
                'clock_hz', 0.0, 'publish /clock at this rate when > 0', bounds=(0.0, MAX_CLOCK_HZ)
            ),
            'delay': param(
                'delay', 0.0, 'seconds to wait before playing', bounds=(0.0, MAX_WAIT_S)
            ),
            'wait_timeout': param(
                'wait_timeout',
                5.0,
                'seconds to wait at most for subscribers before playing; 0 = do not wait',
                bounds=(0.0, MAX_WAIT_S),
            ),
            'start_paused': param('start_paused', False, 'start paused'),
            'strict': param(
                'strict',
                False,
                'refuse a bag with a damaged record (checked before '
                'playing) instead of skipping it',
            ),
        }
        self.rate = param('rate', 1.0, 'playback speed factor (> 0)', read_only=False)
        if not settings['bag']:
            raise StartupError('parameter bag is required: the bag directory or .mcap/.db3 file')
        for name in ('start_offset', 'clock_hz', 'delay', 'wait_timeout'):
            if not (math.isfinite(settings[name]) and settings[name] >= 0):
                raise StartupError(
                    f'parameter {name} must be a finite number >= 0, got {settings[name]}'
                )
        if not self._rate_ok(self.rate):
            raise StartupError(f'parameter rate must be a finite number > 0, got {self.rate}')
        return settings

    def _create_publishers(self, settings: dict) -> List[str]:
        """One publisher per played topic of an installed type; the names, for the log."""
        topics = [self._bag.topic(t).topic for t in settings['topics']] or list(self._bag.topics)
        remaps = parse_remaps(settings['remap'], self._bag)
        classes, skipped = playable(self._bag, topics)
        if not classes:
            raise StartupError(
                f'nothing to play in bag {self._bag.path}: the message types of '
                f'its topics are not installed: {", ".join(skipped)}'
            )
        if skipped:
            self.get_logger().warn(
                f'skipping topics whose message type is not installed: {", ".join(skipped)}'
            )
        self._outputs = {}
        for topic, cls in classes.items():
            info = self._bag.topics[topic]
            qos = adapted_qos(offered_policies(info), HistoryPolicy.KEEP_LAST, DEPTH)
            self._outputs[topic] = self.create_publisher(cls, remaps.get(topic, topic), qos)
        return [f'{t} -> {remaps[t]}' if t in remaps else t for t in classes]

    def _check_records(self, first_ns: int) -> None:
        """``strict``: read every message to be played once; BagError at a damaged one."""
        for _ in self._bag.messages(list(self._outputs), start_ns=first_ns):
            pass

    def _loop_gap_ns(self) -> int:
        """Bag time from the last message to the first one again: one mean message spacing."""
        count, span = self._bag.message_count, self._bag.end_ns - self._bag.start_ns
        if count < 2 or span <= 0:
            return int(LOOP_GAP_ONE_MESSAGE * 1e9)
        return span // (count - 1)

    def _report_damage(self) -> None:
        """The one WARN at the first damaged record skipped."""
        if self._bag.corrupt and not self._warned_damage:
            self._warned_damage = True
            self.get_logger().warn(
                f'skipping damaged records of {self._bag.path} (first: '
                f'{self._bag.damage}); they are counted, and strict:=true '
                f'refuses such a bag'
            )

    def _create_timers_and_services(self, clock_hz: float) -> None:
        self.add_on_set_parameters_callback(self._validate_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)
        self._timer = self.create_timer(TICK, self._tick)
        if clock_hz > 0:
            self._clock_pub = self.create_publisher(
                Clock, '/clock', QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)
            )
            self._clock_timer = self.create_timer(1.0 / clock_hz, self._publish_clock)
        self.create_service(Trigger, '~/pause', self._on_pause)
        self.create_service(Trigger, '~/resume', self._on_resume)
        self.create_service(Trigger, '~/play_next', self._on_play_next)

    @staticmethod
    def _rate_ok(rate) -> bool:
        return isinstance(rate, float) and math.isfinite(rate) and rate > 0

    def _validate_parameters(self, params) -> SetParametersResult:
        for param in params:
            if param.name == 'rate' and not self._rate_ok(param.value):
                return SetParametersResult(
                    successful=False, reason='rate must be a finite number > 0'
                )
        return SetParametersResult(successful=True)

    def _apply_parameters(self, params) -> None:
        for param in params:
            if param.name == 'rate':
                self._playback.set_rate(param.value, time.monotonic_ns())
                self.rate = param.value

    def bag_time_ns(self) -> int:
        """Current playback time on the bag's log-time axis, ns."""
        return self._playback.bag_time_ns(time.monotonic_ns())

    # -- publishing -------------------------------------------------------------------------------

    def _unmatched(self):
        """The played topics (with messages) without a subscriber, and how many are played."""
        played = [t for t in self._outputs if self._bag.topics[t].count]
        return [t for t in played if self._outputs[t].get_subscription_count() == 0], len(played)

    def _begin_if_ready(self, now_ns: int) -> bool:
        """Start the playback once the :class:`StartGate` opens; whether it has started."""
        if self._playback.started:
            return True
        missing, played = self._unmatched()
        if not self._gate.is_open(now_ns, not missing, len(missing) < played):
            return False
        if self._gate.timed_out:
            self.get_logger().warn(
                f'no subscriber on {", ".join(missing)} after wait_timeout; playing anyway'
            )
        elif self._gate.partial:
            self.get_logger().info(
                f'playing: no subscriber on {", ".join(missing)} (yet); the '
                'topics with one do not wait for them'
            )
        self._playback.start(now_ns)
        return True

    def _publish(self, message) -> None:
        self._outputs[message.topic].publish(message.data)
        self.published += 1

    def _tick(self) -> None:
        """Publish every message that is due; at the end, loop or finish."""
        now = time.monotonic_ns()
        if self.finished or not self._begin_if_ready(now):
            return
        loops = self._playback.loops
        try:
            for message in self._playback.due(now):
                self._publish(message)
        except BagError as err:
            self.get_logger().error(str(err))
            self.exit_code = 1
            self._finish()
            return
        self._report_damage()
        if self._playback.loops != loops:
            self.get_logger().info(
                f'end of bag, looping (pass {self._playback.loops + 1})',
                throttle_duration_sec=LOOP_LOG_PERIOD,
            )
        if self._playback.finished:
            self._finish()

    def _finish(self) -> None:
        for publisher in self._outputs.values():
            publisher.wait_for_all_acked(Duration(seconds=ACK_TIMEOUT))
        skipped = f', {self._bag.corrupt} damaged records skipped' if self._bag.corrupt else ''
        self.get_logger().info(f'end of bag: {self.published} messages published{skipped}')
        self.finished = True
        self._timer.cancel()

    def _publish_clock(self) -> None:
        ns = self.bag_time_ns()
        self._clock_pub.publish(
            Clock(clock=Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000))
        )

    # -- services ---------------------------------------------------------------------------------

    def pause(self) -> bool:
        """Pause playback; False if already paused."""
        return self._playback.pause(time.monotonic_ns())

    def resume(self) -> bool:
        """Resume playback where it was paused; False if not paused."""
        return self._playback.resume(time.monotonic_ns())

    def _on_pause(self, _request, response):
        response.success = self.pause()
        response.message = 'paused' if response.success else 'already paused'
        return response

    def _on_resume(self, _request, response):
        response.success = self.resume()
        response.message = 'resumed' if response.success else 'not paused'
        return response

    def _on_play_next(self, _request, response):
        response.success = False
        if not self._playback.paused:
            response.message = 'play_next needs playback paused'
            return response
        try:
            message = self._playback.play_next(time.monotonic_ns())
        except BagError as err:
            response.message = str(err)
            return response
        if message is None:
            response.message = 'no message left'
            return response
        self._publish(message)
        response.success = True
        response.message = f'published {message.topic} logged at {message.log_time_ns} ns'
        return response

    def destroy_node(self) -> None:
        """Close the bag, then destroy the node."""
        self._bag.close()
        super().destroy_node()


def main(args=None) -> int:
    """Entry point of the ``bag_replayer`` executable."""
    return run(BagReplayer, args, done=lambda node: node.finished)


if __name__ == '__main__':
    raise SystemExit(main())
