# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Throughput and latency of estimator_node; prints figures (not a test). About 1-2 minutes.

    .venv/bin/python benchmarks/bench_node.py
    .venv/bin/python benchmarks/bench_node.py --input-type all      # one line per input type
    .venv/bin/python benchmarks/bench_node.py --input-type sensor_msgs/msg/Imu ...

With ``--input-type`` (repeatable, or ``all``) the run is the per-type comparison only: for each
type, the node (``input_type`` set, its default component; JointState: 3 joints, the middle one
estimated) against an empty callback subscribed to the same type, EventsExecutor, one line per
type. Without it, the executor comparison below on WrenchStamped.

Loss test. A publisher in another process (reliable QoS, history 1000) sends samples
of a 1.33 Hz sine (stamps of a notional 500 Hz stream) at a paced rate for one second; the
subscriber in this process spins its executor until nothing more arrives and counts what its
callback got. A rate passes when received == sent in REPEATS trials in a row. The subscription
has the node's QoS (best effort, history 5000): a sample is lost when the history overflows before
the executor takes it, the loss a real best-effort sensor stream suffers. Rates rise and stop at
the first loss, or when the publisher cannot reach the rate (then the figure is a lower bound).
An empty-callback subscriber with the same QoS, the ceiling of a Python node, takes turns with
the node at each rate (same background load). Both run under SingleThreadedExecutor and
EventsExecutor, each spun by ``spin_once`` (a blocking EventsExecutor.spin() neither fires timers
nor returns on shutdown in this rclpy). History 5 (the sensor-data default) is tried as well.

Latency: callback entry of the converging sample to the return of the reset publication
(perf_counter around the node's callback), over every estimate of the node's trials; end to end:
callback entry to the receipt of ``vibration/reset`` by a subscriber in the same process and
executor, with the input at 1 kHz (stamps of a notional 100 Hz stream, for ~26 estimates/s).
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import threading
import time

import numpy as np

os.environ.setdefault('ROS_DOMAIN_ID', str(100 + os.getpid() % 100))
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

# the node's own input history, used for the empty subscriber too (imported after the env is set)
from vib_estimator.io.fields import (  # noqa: E402
    INPUT_TYPES,
    check_input_type,  # noqa: E402
)
from vib_estimator.io.fields import WRENCH_STAMPED as WRENCH
from vib_estimator.nodes.estimator_node import INPUT_DEPTH as DEPTH  # noqa: E402

RATES = [1000, 2000, 3000, 4500, 6500, 9000, 11000, 13000, 15000, 17500, 20000, 25000, 35000]
TRIAL_S = 1.0
REPEATS = 2  # a rate passes when this many trials in a row lose nothing
JOINTS = ['joint0', 'joint1', 'joint2']  # JointState: the default component is effort[joint1]


# ---- publisher process --------------------------------------------------------------------
def publisher(topic: str, input_type: str) -> None:
    """Read ``rate count fs`` lines on stdin; publish, paced; answer ``sent elapsed`` lines."""
    import rclpy
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    from vib_estimator.io.fields import (
        DEFAULT_COMPONENT,
        JOINT_STATE,
        component_setter,
        has_header,
    )
    from vib_estimator.nodes.estimator_node import message_class

    rclpy.init()
    node = rclpy.create_node('bench_publisher')
    pub = node.create_publisher(
        message_class(input_type),
        topic,
        QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE),
    )
    while pub.get_subscription_count() < 1:
        time.sleep(0.01)
    time.sleep(0.5)  # let discovery settle in both directions
    print('ready', flush=True)
    msg = message_class(input_type)()
    stamped = has_header(input_type)
    if stamped:
        msg.header.frame_id = 'bench'
    if input_type == JOINT_STATE:
        msg.name = JOINTS
        msg.effort = [0.0] * len(JOINTS)
    set_value = component_setter(DEFAULT_COMPONENT[input_type], input_type)
    k = 0
    for line in sys.stdin:
        rate, count, fs = (float(x) for x in line.split())
        start = time.perf_counter()
        for i in range(int(count)):
            due = start + i / rate
            while time.perf_counter() < due:
                pass
            k += 1
            if stamped:
                msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(
                    1_000_000_000_000_000_000 + round(k * 1e9 / fs), 10**9
                )
            set_value(msg, math.sin(2 * math.pi * 1.33 * k / fs))
            pub.publish(msg)
        print(int(count), time.perf_counter() - start, flush=True)
    node.destroy_node()
    rclpy.try_shutdown()


# ---- subscriber side ----------------------------------------------------------------------
def make_subscriber(kind, context, topic, depth, input_type):
    """(node, received()) for kind 'node' (the estimator, timed) or 'empty'."""
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from rclpy.qos import QoSProfile, qos_profile_sensor_data

    import vib_estimator.nodes.estimator_node as en

    if kind == 'empty':
        node = Node('empty_subscriber', context=context)
        count = [0]

        def callback(msg):
            count[0] += 1

        node.create_subscription(
            en.message_class(input_type),
            topic,
            callback,
            QoSProfile(depth=depth, reliability=qos_profile_sensor_data.reliability),
        )
        return node, lambda: count[0]

    class TimedNode(en.EstimatorNode):
        """The estimator node, with its callback timed when it publishes an estimate."""

        latencies = []
        entries = {}  # stamp ns of converging samples -> perf_counter at callback entry

        def _on_stamped(self, msg):
            entry = time.perf_counter()
            before = self._stream.health.last_estimate
            super()._on_stamped(msg)
            if self._stream.health.last_estimate is not before:
                self.latencies.append(time.perf_counter() - entry)
                self.entries[msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec] = entry

    en.INPUT_DEPTH = depth
    node = TimedNode(
        context=context,
        parameter_overrides=[
            Parameter('input_topic', value=topic),
            Parameter('input_type', value=input_type),
        ],
    )
    return node, lambda: node.counters['received'] + node.counters['skipped_joint_missing']


class Rig:
    """A subscriber in its own context and executor, spun by spin_once in a thread, and its
    publisher process."""

    def __init__(self, kind, executor_name, depth, topic, extra_nodes=(), input_type=WRENCH):
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.experimental import EventsExecutor

        self.label = f'{kind:5s} {executor_name:6s} depth {depth:3d}'
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node, self.received = make_subscriber(kind, self.context, topic, depth, input_type)
        self.nodes = [self.node] + [make(self.context) for make in extra_nodes]
        self.executor = (EventsExecutor if executor_name == 'events' else SingleThreadedExecutor)(
            context=self.context
        )
        for node in self.nodes:
            self.executor.add_node(node)
        self.running = True
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()
        self.pub = subprocess.Popen(
            [sys.executable, __file__, '--publisher', topic, input_type],
            text=True,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
        )
        assert self.pub.stdout.readline().strip() == 'ready'
        # the subscriber must have matched the publisher too (best effort drops until then)
        while self.node.count_publishers(topic) < 1:
            time.sleep(0.01)
        self.trial(1000, 200)  # warm-up (first calls, caches), not counted

    def _spin(self):
        while self.running:
            self.executor.spin_once(timeout_sec=0.05)

    def trial(self, rate, count, fs=500):
        """Publish ``count`` samples at ``rate``; (sent, received, achieved publisher rate)."""
        base = self.received()
        self.pub.stdin.write(f'{rate} {count} {fs}\n')
        self.pub.stdin.flush()
        sent, elapsed = self.pub.stdout.readline().split()
        last, quiet_since = -1, time.monotonic()
        while time.monotonic() - quiet_since < 0.3:  # until nothing more arrives
            time.sleep(0.02)
            if self.received() != last:
                last, quiet_since = self.received(), time.monotonic()
        return int(sent), self.received() - base, int(sent) / float(elapsed)

    def close(self):
        self.pub.stdin.close()
        self.pub.wait(timeout=10)
        self.running = False
        self.thread.join()
        self.executor.shutdown()
        for node in self.nodes:
            node.destroy_node()
        self.context.try_shutdown()


def ramp(rigs, log, rates=RATES):
    """Highest zero-loss rate of each rig, the rigs taking turns at each rate (same load)."""
    best = {rig: 0 for rig in rigs}
    alive = list(rigs)
    for rate in rates:
        for rig in list(alive):
            for _ in range(REPEATS):
                sent, got, achieved = rig.trial(rate, int(rate * TRIAL_S))
                log(
                    f'  {rig.label}: target {rate:6d}/s, sent {sent:6d} at {achieved:6.0f}/s, '
                    f'received {got:6d} ({100 * (sent - got) / sent:.2f} % lost)'
                )
                if got < sent:
                    alive.remove(rig)
                    break
            else:
                best[rig] = rate
                if achieved < 0.9 * rate:
                    log('  publisher cannot keep up: the figure is a lower bound')
                    alive.remove(rig)
        if not alive:
            break
    return best


def end_to_end(topic):
    """Callback entry of converging samples to receipt of vibration/reset, input at 1 kHz."""
    from std_msgs.msg import Header

    received = {}

    def listener(context):
        import rclpy

        node = rclpy.create_node('reset_listener', context=context)
        node.create_subscription(
            Header,
            'vibration/reset',
            lambda m: received.setdefault(
                m.stamp.sec * 10**9 + m.stamp.nanosec, time.perf_counter()
            ),
            100,
        )
        return node

    rig = Rig('node', 'events', DEPTH, topic, extra_nodes=[listener])
    rig.node.entries.clear()
    rig.trial(1000, 5000, fs=100)
    rig.close()
    return [received[s] - rig.node.entries[s] for s in rig.node.entries if s in received]


def percentiles(values):
    v = np.asarray(values) * 1e6
    return f'p50 {np.percentile(v, 50):7.1f} us, p99 {np.percentile(v, 99):7.1f} us (n={len(v)})'


def cpu_per_message(rig, rate=1000, count=1000, trials=3):
    """Process CPU seconds per message received while ``rig`` takes ``count`` messages at ``rate``
    (median of ``trials``): the subscriber's whole cost (DDS threads, rclpy, the callback), far
    less sensitive to other processes' load than the highest rate."""
    costs = []
    for _ in range(trials):
        base, cpu = rig.received(), time.process_time()
        rig.trial(rate, count)
        costs.append((time.process_time() - cpu) / max(1, rig.received() - base))
    return float(np.median(costs))


def per_type(input_types, log):
    """Node and empty callback of each input type (EventsExecutor): one line per type."""
    results = {}
    for input_type in input_types:
        short = input_type.split('/')[-1].lower()
        rigs = [
            Rig(kind, 'events', DEPTH, f'bench_{kind}_{short}', input_type=input_type)
            for kind in ('empty', 'node')
        ]
        best = ramp(rigs, log)
        results[input_type] = (
            best[rigs[1]],
            best[rigs[0]],
            cpu_per_message(rigs[1]),
            cpu_per_message(rigs[0]),
        )
        for rig in rigs:
            rig.close()
    log('')
    log(
        f'highest input rate with zero loss per input type (msgs/s; EventsExecutor, best effort, '
        f'history {DEPTH}; goal ratio >= 0.9):'
    )
    log(
        f'  {"input type":34s} {"estimator_node":>15s} {"empty callback":>15s} {"ratio":>6s}'
        f'   CPU us/msg: {"node":>6s} {"empty":>6s} {"ratio":>6s}'
    )
    for input_type, (n, e, cpu_n, cpu_e) in results.items():
        log(
            f'  {input_type:34s} {n:15d} {e:15d} {n / e if e else math.nan:6.2f}'
            f'               {1e6 * cpu_n:6.1f} {1e6 * cpu_e:6.1f} {cpu_e / cpu_n:6.2f}'
        )
    log(
        '  (CPU us/msg: process CPU time per message received at 1000/s, median of 3 trials; '
        'its ratio empty/node is the rate ratio a saturated core would give)'
    )


def executors(log):
    """The executor comparison on WrenchStamped, history 5, and the latencies."""
    results = {}
    for executor_name in ('single', 'events'):
        rigs = {
            kind: Rig(kind, executor_name, DEPTH, f'bench_{kind}_{executor_name}')
            for kind in ('empty', 'node')
        }
        best = ramp(list(rigs.values()), log)
        for kind, rig in rigs.items():
            results[kind, executor_name] = best[rig]
            rig.close()
    latencies = list(rigs['node'].node.latencies)  # the EventsExecutor trials
    shallow = Rig('node', 'events', 5, 'bench_node_depth5')
    rate5 = ramp([shallow], log, rates=[500, 1000, 2000])[shallow]
    shallow.close()
    e2e = end_to_end('bench_node_e2e')
    log('')
    log(f'highest input rate with zero loss (msgs/s; best effort, history {DEPTH}):')
    log(f'  {"executor":16s} {"estimator_node":>15s} {"empty callback":>15s} {"ratio":>6s}')
    for executor_name, label in (('single', 'SingleThreaded'), ('events', 'EventsExecutor')):
        n, e = results['node', executor_name], results['empty', executor_name]
        log(f'  {label:16s} {n:15d} {e:15d} {n / e if e else math.nan:6.2f}')
    log(
        f'  estimator_node, EventsExecutor, history 5 (sensor-data default): {rate5}'
        ' (0: lost samples at 500/s)'
    )
    log('latency, converging sample -> estimate published:')
    log(f'  inside the callback (EventsExecutor trials):  {percentiles(latencies)}')
    if e2e:
        log(f'  end to end, same-process subscriber, 1 kHz:  {percentiles(e2e)}')


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        '--input-type',
        action='append',
        metavar='TYPE',
        help=f'an input type ({", ".join(INPUT_TYPES)}) or all; repeatable',
    )
    args = parser.parse_args(argv)
    try:
        types = (
            None
            if not args.input_type
            else list(INPUT_TYPES)
            if 'all' in args.input_type
            else list(dict.fromkeys(check_input_type(t) for t in args.input_type))
        )
    except ValueError as err:
        parser.exit(2, f'error: {err}\n')

    def log(text):
        print(text, flush=True)

    log(
        f'estimator_node benchmark, {os.cpu_count()} cores, ROS_DOMAIN_ID '
        f'{os.environ["ROS_DOMAIN_ID"]}; trials of {TRIAL_S:.0f} s x {REPEATS}'
    )
    if types:
        per_type(types, log)
    else:
        executors(log)


if __name__ == '__main__':
    if sys.argv[1:2] == ['--publisher']:
        publisher(sys.argv[2], sys.argv[3])
    else:
        main()
