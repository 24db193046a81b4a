# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``bag_recorder``: record topics of any message type into a rosbag2 bag (MCAP storage).

A stand-in for ``ros2 bag record`` where only rclpy is installed. Each topic of ``topics`` is
subscribed once a publisher of it appears on the graph (its type is taken from the graph), with a
raw subscription, so messages are stored as the CDR bytes received, never deserialised. The bag is
a rosbag2 directory written by :class:`vib_estimator.io.bags.BagWriter`; log time = receive time on
the node's clock, as rosbag2 does. The publishers' offered QoS profiles are recorded per topic.

Loss: the subscriptions are KEEP_ALL and, when every publisher of the topic is reliable, reliable
(rosbag2's adaptive QoS), so a sample the reader has not taken is never acknowledged or dropped; a
reliable publisher then keeps it until the recorder has it. A best-effort publisher can still lose
samples on the wire -- that is its contract.

Stops on SIGINT (the bag is then closed, complete and readable), after ``duration`` seconds, or
after ``max_messages`` messages.

Crash safety. Every ``flush_period`` s (steady clock) the messages received so far are put into
the storage file (MCAP: the pending chunk is closed, flushed and fsynced; sqlite3: a commit), and
``metadata.yaml`` is written at start and each time a file is opened or closed. After SIGKILL,
power loss or the OOM killer, at most the last ``flush_period`` s are lost;
``vib-estimator reindex BAG`` then rebuilds the index and ``metadata.yaml`` from the storage files.
A write that fails (disk full, file too large, I/O error) ends the recording with one ``error:``
line and exit code 2; what was flushed before stays readable (after ``reindex``).

Splitting, like ``ros2 bag record``: with ``max_bag_duration`` or ``max_bag_size`` > 0 the bag is
written as ``<name>_0.mcap``, ``<name>_1.mcap``, ... (``.db3`` for sqlite3), a new file begun
before a message that would go into a file already that long (log time) or that large.

Parameters (all read-only):
    topics (string[]): topics to record (relative names resolve in the node's namespace).
    output (string): bag directory to create; must not exist.
    storage (string): ``mcap`` (default) or ``sqlite3``.
    duration (double): stop after this many seconds; 0 = until SIGINT.
    max_messages (int): stop after this many messages in all; 0 = no limit.
    flush_period (double, 1.0): seconds between flushes to the storage file, > 0.
    max_bag_duration (double, 0): split after this many seconds of log time per file; 0 = never.
    max_bag_size (int, 0): split when a file reaches this many bytes; 0 = never.
"""

from __future__ import annotations

import importlib
import math
import sys
from functools import partial
from typing import Dict, Iterable, Tuple

from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from ..errors import BagError, StartupError
from ..io.bags import STORAGES, BagWriter, bag_qos
from .parameters import declare, descriptor
from .runner import run

DISCOVERY_PERIOD = 0.05  # s between looks at the graph for publishers of topics not yet recorded


def message_class(msgtype: str):
    """The rclpy message class of ``pkg/msg/Name``; ``ImportError`` if not installed."""
    parts = msgtype.split('/')
    if len(parts) != 3 or parts[1] != 'msg':
        raise ImportError(f'{msgtype!r} is not a message type name (pkg/msg/Name)')
    try:
        return getattr(importlib.import_module(f'{parts[0]}.msg'), parts[2])
    except (ImportError, AttributeError):
        raise ImportError(f'message type {msgtype} is not installed') from None


def adapted_qos(
    offered: Iterable[Tuple[ReliabilityPolicy, DurabilityPolicy]],
    history: HistoryPolicy,
    depth: int = 0,
) -> QoSProfile:
    """A QoS profile that matches every offered (reliability, durability) pair.

    rosbag2's adaptive rule: reliable only if every publisher offers reliable (a reliable reader
    does not match a best-effort writer), transient-local only if every publisher offers it. With
    no offer known, reliable and volatile.
    """
    offered = list(offered)
    reliable = all(r == ReliabilityPolicy.RELIABLE for r, _ in offered)
    latched = bool(offered) and all(d == DurabilityPolicy.TRANSIENT_LOCAL for _, d in offered)
    return QoSProfile(
        history=history,
        depth=depth,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
    )


class BagRecorder(Node):
    """Records ``topics`` into the bag ``output``; see the module docstring."""

    def __init__(self, **kwargs) -> None:
        super().__init__('bag_recorder', **kwargs)
        settings = self._declare_parameters()
        try:
            self._pending = {self.resolve_topic_name(t) for t in settings['topics']}
        except Exception as err:  # rclpy's RCLError, which it does not export
            raise StartupError(f'invalid topic name in {settings["topics"]}: {err}') from None
        output = settings['output']
        try:
            self._bag = BagWriter(
                output,
                settings['storage'],
                settings['max_bag_size'],
                int(round(settings['max_bag_duration'] * 1e9)),
            ).open()
        except BagError as err:
            raise StartupError(str(err)) from None
        except OSError as err:
            raise StartupError(f'cannot create bag {output}: {err}') from None

        #: messages recorded, per topic
        self.counts: Dict[str, int] = {}
        self.message_count = 0
        #: set when ``duration`` or ``max_messages`` is reached or writing failed; :func:`main`
        #: then exits with ``exit_code``
        self.finished = False
        self.exit_code = 0
        self._discovery = self.create_timer(DISCOVERY_PERIOD, self._discover)
        self.create_timer(
            settings['flush_period'], self._flush, clock=Clock(clock_type=ClockType.STEADY_TIME)
        )
        if settings['duration'] > 0:
            self.create_timer(settings['duration'], self._stop)
        self.get_logger().info(
            f'recording {", ".join(sorted(self._pending))} into {output} ({settings["storage"]})'
        )

    def _declare_parameters(self) -> dict:
        def param(name, default, description):
            return declare(self, name, default, descriptor(description, read_only=True))

        settings = {
            'topics': param('topics', Parameter.Type.STRING_ARRAY, 'topics to record') or [],
            'output': param('output', '', 'bag directory to create (must not exist)'),
            'storage': param('storage', 'mcap', f'storage plugin: {" or ".join(STORAGES)}'),
            'duration': param('duration', 0.0, 'stop after this many seconds; 0 = until SIGINT'),
            'flush_period': param(
                'flush_period',
                1.0,
                'seconds between flushes of the recorded '
                'messages to the storage file (crash safety)',
            ),
            'max_bag_duration': param(
                'max_bag_duration',
                0.0,
                'split the bag into files of at most this many seconds; 0 = no split',
            ),
            'max_bag_size': param(
                'max_bag_size',
                0,
                'split the bag into files of at most about this many bytes; 0 = no split',
            ),
        }
        self.max_messages = param(
            'max_messages', 0, 'stop after this many messages in all; 0 = no limit'
        )
        if not settings['topics']:
            raise StartupError(
                'parameter topics is empty: give the topics to record, e.g. '
                '-p topics:="[/coupling_torque]"'
            )
        if not settings['output']:
            raise StartupError('parameter output is empty: give the bag directory to create')
        if settings['storage'] not in STORAGES:
            raise StartupError(
                f'parameter storage must be one of {", ".join(STORAGES)}, '
                f'got {settings["storage"]!r}'
            )
        if (
            min(
                settings['duration'],
                self.max_messages,
                settings['max_bag_duration'],
                settings['max_bag_size'],
            )
            < 0
        ):
            raise StartupError(
                'parameters duration, max_messages, max_bag_duration and max_bag_size must be >= 0'
            )
        if not (math.isfinite(settings['flush_period']) and settings['flush_period'] > 0):
            raise StartupError(
                f'parameter flush_period must be a finite number > 0, '
                f'got {settings["flush_period"]}'
            )
        return settings

    def _discover(self) -> None:
        """Subscribe to each pending topic that now has publishers."""
        for topic in sorted(self._pending):
            infos = self.get_publishers_info_by_topic(topic)
            if not infos:
                continue
            types = sorted({info.topic_type for info in infos})
            if len(types) > 1:
                self.get_logger().warn(
                    f'{topic} is published with several types {types}; waiting for one',
                    throttle_duration_sec=5.0,
                )
                continue
            self._pending.discard(topic)
            try:
                cls = message_class(types[0])
                connection = self._bag.add_topic(
                    topic, types[0], [bag_qos(i.qos_profile) for i in infos]
                )
            except (ImportError, BagError) as err:
                self.get_logger().error(f'not recording {topic}: {err}')
                continue
            qos = adapted_qos(
                ((i.qos_profile.reliability, i.qos_profile.durability) for i in infos),
                HistoryPolicy.KEEP_ALL,
            )
            self.create_subscription(
                cls, topic, partial(self._on_message, connection), qos, raw=True
            )
            self.counts[topic] = 0
            self.get_logger().info(
                f'recording {topic} ({types[0]}, {qos.reliability.name.lower()})'
            )
        if self._pending:
            self.get_logger().info(
                f'waiting for publishers on {", ".join(sorted(self._pending))}',
                throttle_duration_sec=5.0,
            )
        else:
            self._discovery.cancel()

    def _on_message(self, connection, data: bytes) -> None:
        if self.finished:
            return
        try:
            self._bag.write(connection, self.get_clock().now().nanoseconds, data)
        except BagError as err:
            self._fail(err)
            return
        self.counts[connection.topic] += 1
        self.message_count += 1
        if self.max_messages and self.message_count >= self.max_messages:
            self._stop()

    def _flush(self) -> None:
        try:
            self._bag.flush()
        except BagError as err:
            self._fail(err)

    def _fail(self, err: BagError) -> None:
        """Stop recording after a failed write: one ``error:`` line (the first failure),
        exit code 2."""
        if self.exit_code != 2:
            print(f'error: {err}', file=sys.stderr, flush=True)
        self.exit_code = 2
        self.finished = True

    def _stop(self) -> None:
        self.finished = True

    def destroy_node(self) -> None:
        """Close the bag (index and metadata.yaml written), then destroy the node."""
        try:
            self._bag.close()
        except BagError as err:
            self._fail(err)
        self.get_logger().info(
            f'recorded {self.message_count} messages: '
            + (
                ', '.join(f'{t} {n}' for t, n in sorted(self.counts.items()))
                or 'no topic had a publisher'
            )
        )
        super().destroy_node()


def main(args=None) -> int:
    """Entry point of the ``bag_recorder`` executable."""
    return run(BagRecorder, args, done=lambda node: node.finished)


if __name__ == '__main__':
    raise SystemExit(main())
