# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Bursts of 5000 WrenchStamped at full publisher speed into estimator_node; prints, per burst,
what the node received and counted as missing (docs/nodes.md#the-input-qos). About a minute.

    .venv/bin/python benchmarks/burst.py                  # the node's input depth (5000)
    .venv/bin/python benchmarks/burst.py --depth 400      # another depth, for the trade-off

The node runs in a process of its own (``estimator_node``'s main with ``INPUT_DEPTH`` set, its
defaults otherwise); this process publishes (reliable, history 10000) 1000 messages at a live
pace (500 Hz stamps), then each burst (stamps continuing, at full speed), one message 1.5 s later
(a loss at a burst's end is a gap before it), and 1000 live ones between bursts; the node's
counters are read from ``/diagnostics``. Every burst must be received or counted (exit 1 else).
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import time

os.environ.setdefault('ROS_DOMAIN_ID', str(40 + os.getpid() % 60))
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

import rclpy  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from rclpy.qos import QoSProfile, ReliabilityPolicy  # noqa: E402

BURST = 5000
PERIOD_NS = 2_000_000  # 500 Hz stamps
COUNTERS = ('received', 'samples_missing', 'lost_in_queue', 'missing_in_gaps', 'lost_in_transport')
NODE = (
    'import sys; from vib_estimator.nodes import estimator_node as e; '
    'e.INPUT_DEPTH = int(sys.argv[1]); sys.exit(e.main(sys.argv[2:]))'
)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--depth', type=int, default=5000, help="the node's input history depth")
    parser.add_argument('--bursts', type=int, default=3)
    args = parser.parse_args(argv)
    node_proc = subprocess.Popen(
        [sys.executable, '-c', NODE, str(args.depth)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    rclpy.init()
    node = rclpy.create_node('burster')
    last = {}

    def on_diagnostics(msg):
        for status in msg.status:
            if status.name == '/estimator_node':
                last.clear()
                last.update({kv.key: kv.value for kv in status.values})

    node.create_subscription(DiagnosticArray, '/diagnostics', on_diagnostics, 10)
    pub = node.create_publisher(
        WrenchStamped,
        'coupling_torque',
        QoSProfile(depth=10000, reliability=ReliabilityPolicy.RELIABLE),
    )

    def spin(seconds, until=lambda: False):
        end = time.monotonic() + seconds
        while time.monotonic() < end and not until():
            rclpy.spin_once(node, timeout_sec=0.02)

    def count(name):
        return int(last.get(name, 0))

    msg = WrenchStamped()
    sent = [0]

    def send():
        k = sent[0]
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(10**9 + k * PERIOD_NS, 10**9)
        msg.wrench.torque.z = math.sin(k * 0.0167)
        pub.publish(msg)
        sent[0] += 1

    def live():
        for _ in range(1000):
            send()
            spin(0.002)
        spin(2.0)

    failed = False
    try:
        spin(120.0, lambda: pub.get_subscription_count() > 0 and 'received' in last)
        live()
        for _ in range(args.bursts):
            before = {name: count(name) for name in COUNTERS}
            t0 = time.monotonic()
            for _ in range(BURST):
                send()
            rate = BURST / (time.monotonic() - t0)
            spin(1.5)
            send()

            def accounted():
                return sum(count(n) - before[n] for n in ('received', 'samples_missing'))

            spin(10.0, lambda: accounted() >= BURST + 1)
            spin(1.5)
            d = {name: count(name) - before[name] for name in COUNTERS}
            failed |= accounted() < BURST + 1
            print(
                f'depth {args.depth}: burst at {rate:.0f} msg/s: received {d["received"]}, '
                f'samples_missing {d["samples_missing"]} (lost_in_queue {d["lost_in_queue"]}, '
                f'missing_in_gaps {d["missing_in_gaps"]}; lost_in_transport '
                f'{d["lost_in_transport"]}): {accounted()} of {BURST + 1} accounted for',
                flush=True,
            )
            live()
    finally:
        node_proc.send_signal(2)
        node_proc.wait(10)
        node.destroy_node()
        rclpy.try_shutdown()
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
