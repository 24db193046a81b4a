# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""estimator_node's input history as the middleware keeps it (issue 40): Fast DDS 2.14 warns that
a depth of 5000 is 'inconsistent with max_samples_per_instance 400' and 'effectively' uses 400;
for a topic without keys it does not. A reader with the node's input QoS that takes nothing
while a burst of 5100 messages is published keeps the newest 5000 -- a keep-last history of
5000, as docs/nodes.md#the-input-qos says (400 were kept at depth 400; at depth 8000 the
oldest 5000 were kept and the newest dropped, past Fast DDS's max_samples)."""

from __future__ import annotations

from geometry_msgs.msg import WrenchStamped
from rclpy.qos import QoSProfile, ReliabilityPolicy

from vib_estimator.nodes.estimator_node import input_qos
from vib_estimator.nodes.runner import spin_until

#: the burst the node's history is sized for, and a few more (issue 40: 5000 at full speed)
BURST = 5000
EXTRA = 100
MARKER = 10**6


def test_the_input_history_keeps_the_newest_5000_of_a_burst(ros_context, executor):
    from rclpy.node import Node

    reader = Node('history_reader', context=ros_context)
    writer = Node('history_writer', context=ros_context)
    taken = []
    reader.create_subscription(
        WrenchStamped, 'history_probe', lambda m: taken.append(m.header.stamp.sec), input_qos()
    )
    pub = writer.create_publisher(
        WrenchStamped,
        'history_probe',
        QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE),
    )
    executor.add_node(writer)
    assert spin_until(executor, lambda: pub.get_subscription_count() == 1, 10.0)
    msg = WrenchStamped()
    for k in range(BURST + EXTRA):  # the reader is not spun: nothing is taken meanwhile
        msg.header.stamp.sec = k
        pub.publish(msg)
    executor.add_node(reader)
    # all it holds; then a marker, taken after whatever was held before it (no timed wait)
    spin_until(executor, lambda: len(taken) >= BURST, 10.0)
    msg.header.stamp.sec = MARKER
    pub.publish(msg)
    assert spin_until(executor, lambda: taken and taken[-1] == MARKER, 10.0)
    assert taken[:-1] == list(range(EXTRA, BURST + EXTRA)), (len(taken), taken[:3], taken[-3:])
