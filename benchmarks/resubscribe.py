# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Re-create a subscription every 20 ms under rclpy's EventsExecutor while sim_node streams at
speed 10; prints whether the process survived (docs/nodes.md#never-deaf). About a minute a run.

    .venv/bin/python benchmarks/resubscribe.py                 # with a message_lost callback
    .venv/bin/python benchmarks/resubscribe.py --mode none     # without (the watchdog's way)
    .venv/bin/python benchmarks/resubscribe.py --mode skip     # with, InvalidHandle skipped

Each run is a process of its own (a segmentation fault ends it): ``--runs`` of them, each up to
``--count`` re-creations (destroy, then create, as the node's watchdog does), the input QoS of
estimator_node, the process's exit code and what it printed.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

os.environ.setdefault('ROS_DOMAIN_ID', str(30 + os.getpid() % 60))
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

RUN = """
import faulthandler, sys
faulthandler.enable()
from rclpy._rclpy_pybind11 import InvalidHandle
from rclpy.event_handler import SubscriptionEventCallbacks
from geometry_msgs.msg import WrenchStamped
import rclpy
from vib_estimator.nodes.estimator_node import input_qos
from vib_estimator.nodes.runner import make_executor, stall_safe_transports

mode, count = sys.argv[1], int(sys.argv[2])
stall_safe_transports()
rclpy.init()
node = rclpy.create_node('resubscribe')
lost, taken, made, skipped = [0], [0], [0], [0]
events = SubscriptionEventCallbacks(message_lost=lambda info: lost.__setitem__(0, lost[0] + 1))


def subscribe():
    return node.create_subscription(
        WrenchStamped, 'coupling_torque', lambda m: taken.__setitem__(0, taken[0] + 1),
        input_qos(), event_callbacks=None if mode == 'none' else events)


subs = [subscribe()]


def recreate():
    node.destroy_subscription(subs[0])
    subs[0] = subscribe()
    made[0] += 1


node.create_timer(0.02, recreate)
executor = make_executor()
executor.add_node(node)
while made[0] < count:
    try:
        executor.spin_once(timeout_sec=0.1)
    except InvalidHandle:
        if mode != 'skip':
            raise
        skipped[0] += 1
print(f'survived {made[0]} re-creations: took {taken[0]} messages, {lost[0]} lost events, '
      f'{skipped[0]} InvalidHandle skipped')
"""


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--mode', choices=('lost', 'none', 'skip'), default='lost')
    parser.add_argument('--runs', type=int, default=2)
    parser.add_argument('--count', type=int, default=2500)
    args = parser.parse_args(argv)
    here = os.path.dirname(sys.executable)
    sim_node = os.path.join(here, 'sim_node')
    sim = subprocess.Popen(
        [sim_node if os.path.exists(sim_node) else 'sim_node', '--ros-args', '-p', 'speed:=10.0']
        + ['-p', 'excitation:=ambient'],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    failed = 0
    try:
        time.sleep(5.0)  # the simulator up (its own start, not this test's subject)
        for k in range(args.runs):
            t0 = time.monotonic()
            out = subprocess.run(
                [sys.executable, '-c', RUN, args.mode, str(args.count)],
                capture_output=True,
                text=True,
                timeout=900,
            )
            text = (out.stdout + out.stderr).strip().splitlines()
            last = text[-1:]  # survived ..., or the error (a traceback's, faulthandler's first)
            fault = [line for line in text if line.startswith('Fatal Python error')]
            last = fault or last
            failed += out.returncode != 0
            print(
                f'{args.mode} run {k + 1}: exit {out.returncode} after '
                f'{time.monotonic() - t0:.0f} s: {last[0] if last else ""}',
                flush=True,
            )
    finally:
        sim.send_signal(2)
        sim.wait(10)
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
