"""``bag_replayer``: play a rosbag2 bag (MCAP or sqlite3) or a bare ``.mcap``/``.db3`` file.

A stand-in for ``ros2 bag play`` where only rclpy is installed; its parameters carry the names of
``ros2 bag play``'s options. The recorded CDR bytes are published as they are (header stamps
untouched), each on a publisher of its recorded type, in recorded order and with the recorded
spacing of log times divided by ``rate``.

Scheduling. A timer every :data:`TICK` s publishes every message whose due time has passed, so the
timing error is at most one tick and high message rates (or rates x100) do not need one timer event
per message. Playback time is ``bag_time = anchor_bag + (now - anchor_wall) * rate`` on the steady
clock; pausing, resuming, changing ``rate`` and looping move the anchors.

QoS. Each publisher offers what the bag recorded as offered for its topic (reliable unless every
recorded publisher was best effort; transient-local only if every one was), keep-last 1000 deep;
without a recorded profile, reliable depth 1000. A best-effort subscriber (sensor-data QoS, like the
estimator node's) matches a reliable publisher.

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
    start_paused (bool, false): start paused (see the services).

Services (``std_srvs/srv/Trigger``):
    ~/pause: pause playback (and ``/clock``). ~/resume: resume it.
    ~/play_next: while paused, publish the next message at once.

Exits 0 at the end of the bag (unless looping); a bag that cannot be played (missing, corrupt,
truncated, empty, unknown topic or message type) gives one line on stderr and exit code 2.
"""
from __future__ import annotations

import math
import time
from typing import Dict, List, Optional

from builtin_interfaces.msg import Time
from rcl_interfaces.msg import SetParametersResult
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rosbags.interfaces import QosDurability, QosReliability
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Trigger

from ..io.bags import BagError, BagReader, TopicInfo
from .bag_recorder import adapted_qos, message_class
from .runner import StartupError, run
from .parameters import declare, descriptor

TICK = 0.001  # s, period of the scheduling timer
DEPTH = 1000  # history depth of the publishers
ACK_TIMEOUT = 2.0  # s to wait at the end for reliable subscribers to acknowledge everything


def offered_policies(info: TopicInfo):
    """(reliability, durability) rclpy policies of each QoS profile recorded for a bag topic."""
    return [(ReliabilityPolicy.BEST_EFFORT if q.reliability == QosReliability.BEST_EFFORT
             else ReliabilityPolicy.RELIABLE,
             DurabilityPolicy.TRANSIENT_LOCAL if q.durability == QosDurability.TRANSIENT_LOCAL
             else DurabilityPolicy.VOLATILE) for q in info.offered_qos]


def parse_remaps(remap: List[str], bag: BagReader) -> Dict[str, str]:
    """``['old:=new', ...]`` -> ``{old: new}``; ``StartupError`` for a bad rule or unknown topic."""
    rules = {}
    for rule in remap:
        old, sep, new = rule.partition(':=')
        if not (sep and old and new):
            raise StartupError(f'parameter remap: {rule!r} is not of the form old:=new')
        bag.topic(old)  # BagError listing the bag's topics if unknown
        rules[old] = new
    return rules


class BagReplayer(Node):
    """Plays the bag of parameter ``bag``; see the module docstring."""

    def __init__(self, **kwargs) -> None:
        super().__init__('bag_replayer', **kwargs)

        def param(name, default, description, read_only=True):
            return declare(self, name, default, descriptor(description, read_only=read_only))

        path = param('bag', '', 'bag directory, or .mcap / .db3 file, to play')
        self.rate = param('rate', 1.0, 'playback speed factor (> 0)', read_only=False)
        self.loop = param('loop', False, 'start over at the end of the bag')
        start_offset = param('start_offset', 0.0, 'seconds of the bag to skip from its start')
        topics = param('topics', Parameter.Type.STRING_ARRAY,
                         'topics to play (default: all)') or []
        remap = param('remap', Parameter.Type.STRING_ARRAY, 'old:=new topic renames') or []
        clock_hz = param('clock_hz', 0.0, 'publish /clock at this rate when > 0')
        delay = param('delay', 0.0, 'seconds to wait before playing')
        start_paused = param('start_paused', False, 'start paused')
        if not path:
            raise StartupError('parameter bag is required: the bag directory or .mcap/.db3 file')
        for name, value in (('start_offset', start_offset), ('clock_hz', clock_hz),
                            ('delay', delay)):
            if not (math.isfinite(value) and value >= 0):
                raise StartupError(f'parameter {name} must be a finite number >= 0, got {value}')
        if not self._rate_ok(self.rate):
            raise StartupError(f'parameter rate must be a finite number > 0, got {self.rate}')

        try:
            self._bag = BagReader(path)
        except BagError as err:
            raise StartupError(str(err)) from None
        #: number of messages published (all loops)
        self.published = 0
        #: set at the end of the bag when not looping; :func:`main` then exits with ``exit_code``
        self.finished = False
        self.exit_code = 0
        self._paused = start_paused
        try:
            self._topics = [self._bag.topic(t).topic for t in topics] or list(self._bag.topics)
            remaps = parse_remaps(remap, self._bag)
            self._outputs = {}
            for topic in self._topics:
                info = self._bag.topics[topic]
                qos = adapted_qos(offered_policies(info), HistoryPolicy.KEEP_LAST, DEPTH)
                self._outputs[topic] = self.create_publisher(
                    message_class(info.msgtype), remaps.get(topic, topic), qos)
            self._first_ns = self._bag.start_ns + int(round(start_offset * 1e9))
            self._restart(time.monotonic_ns() + int(delay * 1e9))
        except (BagError, ImportError, StartupError) as err:
            self._bag.close()
            raise StartupError(str(err)) from None

        self.add_on_set_parameters_callback(self._validate_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)
        self._timer = self.create_timer(TICK, self._tick)
        if clock_hz > 0:
            self._clock_pub = self.create_publisher(
                Clock, '/clock', QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT))
            self._clock_timer = self.create_timer(1.0 / clock_hz, self._publish_clock)
        self.create_service(Trigger, '~/pause', self._on_pause)
        self.create_service(Trigger, '~/resume', self._on_resume)
        self.create_service(Trigger, '~/play_next', self._on_play_next)
        names = [f'{t} -> {remaps[t]}' if t in remaps else t for t in self._topics]
        self.get_logger().info(f'playing {path}: {", ".join(names)} at rate {self.rate}'
                               + (', paused' if start_paused else ''))

    @staticmethod
    def _rate_ok(rate) -> bool:
        return isinstance(rate, float) and math.isfinite(rate) and rate > 0

    def _validate_parameters(self, params) -> SetParametersResult:
        for param in params:
            if param.name == 'rate' and not self._rate_ok(param.value):
                return SetParametersResult(successful=False,
                                           reason='rate must be a finite number > 0')
        return SetParametersResult(successful=True)

    def _apply_parameters(self, params) -> None:
        for param in params:
            if param.name == 'rate':
                self._anchor(self.bag_time_ns())
                self.rate = param.value

    # -- playback time ----------------------------------------------------------------------------

    def _anchor(self, bag_ns: int, wall_ns: Optional[int] = None) -> None:
        """Playback time is ``bag_ns`` at steady time ``wall_ns`` (default: now)."""
        self._anchor_bag = bag_ns
        self._anchor_wall = time.monotonic_ns() if wall_ns is None else wall_ns

    def bag_time_ns(self) -> int:
        """Current playback time on the bag's log-time axis, ns."""
        elapsed = time.monotonic_ns() - self._anchor_wall
        if self._paused or elapsed <= 0:
            return self._anchor_bag
        return self._anchor_bag + int(elapsed * self.rate)

    def _restart(self, wall_ns: Optional[int] = None) -> None:
        """Go back to ``start_offset`` of the bag, to be played from steady time ``wall_ns``.

        Sets ``_messages`` (the iterator over the bag) and ``_next`` (the next message to play).
        """
        self._messages = self._bag.messages(self._topics, start_ns=self._first_ns)
        self._next = next(self._messages, None)
        if self._next is None:
            raise StartupError(f'bag {self._bag.path} has no message to play after start_offset')
        self._anchor(self._first_ns, wall_ns)

    # -- publishing -------------------------------------------------------------------------------

    def _publish_next(self) -> None:
        message = self._next
        self._outputs[message.topic].publish(message.data)
        self.published += 1
        self._next = next(self._messages, None)

    def _tick(self) -> None:
        """Publish every message that is due; at the end, loop or finish."""
        if self._paused or self.finished or time.monotonic_ns() < self._anchor_wall:
            return  # paused, done, or still in the initial delay
        try:
            now = self.bag_time_ns()
            while self._next is not None and self._next.log_time_ns <= now:
                self._publish_next()
            if self._next is None:
                if self.loop:
                    self._restart()
                    self.get_logger().info('end of bag, looping')
                else:
                    self._finish()
        except BagError as err:
            self.get_logger().error(str(err))
            self.exit_code = 1
            self._finish()

    def _finish(self) -> None:
        for publisher in self._outputs.values():
            publisher.wait_for_all_acked(Duration(seconds=ACK_TIMEOUT))
        self.get_logger().info(f'end of bag: {self.published} messages published')
        self.finished = True
        self._timer.cancel()

    def _publish_clock(self) -> None:
        ns = self.bag_time_ns()
        self._clock_pub.publish(Clock(clock=Time(sec=ns // 1_000_000_000,
                                                 nanosec=ns % 1_000_000_000)))

    # -- services ---------------------------------------------------------------------------------

    def pause(self) -> bool:
        """Pause playback; False if already paused."""
        if self._paused:
            return False
        self._anchor(self.bag_time_ns())
        self._paused = True
        return True

    def resume(self) -> bool:
        """Resume playback where it was paused; False if not paused."""
        if not self._paused:
            return False
        self._paused = False
        self._anchor(self._anchor_bag)
        return True

    def _on_pause(self, _request, response):
        response.success = self.pause()
        response.message = 'paused' if response.success else 'already paused'
        return response

    def _on_resume(self, _request, response):
        response.success = self.resume()
        response.message = 'resumed' if response.success else 'not paused'
        return response

    def _on_play_next(self, _request, response):
        if not self._paused:
            response.success, response.message = False, 'play_next needs playback paused'
        elif self._next is None:
            response.success, response.message = False, 'no message left'
        else:
            message = self._next
            try:
                self._publish_next()
            except BagError as err:
                response.success, response.message = False, str(err)
                return response
            self._anchor(message.log_time_ns)
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
