#!/usr/bin/env python3
# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Stream recordings of the temperature fleet through estimator_node with a saved baseline and
print the node's alarms beside survey's rows (docs/health.md):

    python scripts/health_replay.py BASELINE.yaml SURVEY.jsonl DAY_BAG... [--window 300]

In one process (a fresh ROS context, the node and a publisher node on its executor): each bag's
``/accel`` (Imu) and ``/temperature`` messages are published as recorded (serialized), in log-time
order, as fast as the node takes them (the publisher waits until the node has received each
batch); the node runs ``excitation: ambient`` on ``linear_acceleration.z`` with
``baseline_file`` and ``health_window_s`` (each day one window: the bags start at midnight).
``vibration/alarm`` arrives at each window's end, i.e. with the next day's first estimate: the
last bag's day is not judged. The rows of ``SURVEY.jsonl`` (``survey ... --format jsonl`` with the
same baseline) give survey's alarm of each day (any mode).
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import rclpy
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import Imu, Temperature
from std_msgs.msg import Bool

from vib_estimator.io.bags import BagReader
from vib_estimator.nodes.estimator_node import EstimatorNode
from vib_estimator.nodes.runner import make_executor, spin_until

BATCH = 200


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('baseline')
    parser.add_argument('survey')
    parser.add_argument('bags', nargs='+')
    parser.add_argument('--window', type=float, default=300.0)
    args = parser.parse_args(argv)
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=int(os.environ.get('ROS_DOMAIN_ID', '0')))
    params = {
        'input_type': 'sensor_msgs/msg/Imu',
        'input_topic': '/accel',
        'component': 'linear_acceleration.z',
        'excitation': 'ambient',
        'baseline_file': args.baseline,
        'health_window_s': args.window,
    }
    node = EstimatorNode(
        context=context, parameter_overrides=[Parameter(k, value=v) for k, v in params.items()]
    )
    probe = Node('replay', context=context)
    pubs = {
        '/accel': probe.create_publisher(Imu, '/accel', 1000),
        '/temperature': probe.create_publisher(Temperature, '/temperature', 100),
    }
    alarms = []
    sub = probe.create_subscription(Bool, 'vibration/alarm', lambda m: alarms.append(m.data), 100)
    executor = make_executor(context=context)
    executor.add_node(node)
    executor.add_node(probe)
    assert spin_until(
        executor,
        lambda: (
            all(p.get_subscription_count() >= 1 for p in pubs.values())
            and sub.get_publisher_count() >= 1
        ),
        30.0,
    ), 'the node did not subscribe'
    monitor = node.baseline_monitor
    sent = covariates = 0
    for path in args.bags:
        with BagReader(path) as bag:
            for n, message in enumerate(bag.messages(['/accel', '/temperature'])):
                pubs[message.topic].publish(message.data)
                if message.topic == '/accel':
                    sent += 1
                else:
                    covariates += 1
                if n % BATCH == 0:
                    spin_until(
                        executor,
                        lambda: (
                            node.counters['received'] >= sent and monitor.received >= covariates
                        ),
                        30.0,
                    )
        spin_until(executor, lambda: node.counters['received'] >= sent, 30.0)
    rows = [json.loads(line) for line in open(args.survey)]
    survey = {}
    for row in rows:
        if row.get('baseline_mode'):
            survey[row['recording'].rstrip('/')] = (
                survey.get(row['recording'].rstrip('/'), False) or row['alarm']
            )
    print('day                          node alarm  survey alarm (any mode)')
    for path, alarm in zip(args.bags, alarms):
        print(f'{path:<28} {alarm!s:>10}  {survey.get(path.rstrip("/"))!s:>12}')
    print(f'{len(alarms)} windows judged for {len(args.bags)} recordings', file=sys.stderr)
    executor.shutdown()
    node.destroy_node()
    probe.destroy_node()
    context.try_shutdown()
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
