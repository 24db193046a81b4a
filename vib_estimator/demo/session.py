# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The demo's ROS session: its domain, this process's node (:class:`Listener`, recording into a
:class:`Record`) and the node subprocesses it starts and stops (:class:`Session`).

Times are the header stamps in simulated time from the simulator's start (``SIM_TIME_ORIGIN_NS``).
An estimate's time is the stamp of its ``vibration/reset`` (the converging sample; the node
publishes frequency, then reset), and its convergence time the time since the previous reset (since
the start for the first): an estimate the node's quality gate held back also restarts a segment
without a reset message, so this may over-state a few convergence times.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import List, Optional, Sequence, Tuple

from ..core.config import PAPER

#: estimator_node's parameters of the paper's configuration: the demo replays the paper's Section 5
#: (a simulated arm without offset), so its figures stay those of the paper's estimator
PAPER_PARAMS = tuple(f'{name}:={value}' for name, value in PAPER.items())
#: seconds allowed for the nodes to start and see each other
STARTUP_TIMEOUT = 30.0
#: seconds allowed for the estimator node to compile its kernels (a first start after an install
#: that skipped ``make setup``'s warm-up; the node says so on /diagnostics meanwhile)
WARMUP_TIMEOUT = 300.0
#: the domains the demo picks from when neither --domain-id nor ROS_DOMAIN_ID says: Jazzy's
#: 0-101 on Linux, without 0 (every ROS user's default)
DOMAINS = range(1, 102)
#: a subprocess gets this long to exit on SIGINT before it is killed, s
STOP_TIMEOUT = 5.0
#: the ROS domain ids DDS can map to ports (ROS 2 documentation: 0-232)
MAX_DOMAIN_ID = 232


def domain_id(text: str) -> int:
    """``--domain-id``: an integer in [0, :data:`MAX_DOMAIN_ID`] (argparse: error and exit 2)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'not an integer: {text!r}') from None
    if not 0 <= value <= MAX_DOMAIN_ID:
        raise argparse.ArgumentTypeError(f'must be in [0, {MAX_DOMAIN_ID}], got {value}')
    return value


def demo_domain(asked: Optional[int], env: Optional[str]) -> int:
    """The demo's ROS domain: ``--domain-id`` if given (checked by :func:`domain_id`), else
    ``ROS_DOMAIN_ID`` when set to one, else one of :data:`DOMAINS` from the process id."""
    if asked is not None:
        return asked
    if env and env.strip().isdigit() and 0 <= int(env) <= MAX_DOMAIN_ID:
        return int(env)
    return DOMAINS[os.getpid() % len(DOMAINS)]


def sim_params(speed: float, duration: float, schedule, subscribers: int) -> List[str]:
    """sim_node's parameters for a demo run in simulated time."""
    return [
        f'speed:={float(speed)}',
        f'duration:={float(duration)}',
        'publish_clock:=true',
        f'wait_for_subscribers:={subscribers}',
        'schedule:=[' + ', '.join(map(repr, schedule)) + ']',
    ]


@dataclass
class Record:
    """What the demo heard, in seconds of simulated time (the simulator's stamps from its origin).

    ``truth`` is the schedule's (t_start, t_end, f0 of Eq. 23) per mass; ``heard_truth`` the values
    received on ``vibration/ground_truth``.
    """

    truth: List[Tuple[float, float, float]]
    heard_truth: List[float] = field(default_factory=list)
    t: List[float] = field(default_factory=list)  # torque samples
    torque: List[float] = field(default_factory=list)
    est_t: List[float] = field(default_factory=list)
    est_f: List[float] = field(default_factory=list)
    est_conv: List[float] = field(default_factory=list)

    def truth_at(self, t: float) -> float:
        """The true frequency at time t."""
        return next((f for t0, t1, f in self.truth if t < t1), self.truth[-1][2])


class Listener:
    """The demo's own node: records the four topics into a :class:`Record`, printing estimates."""

    def __init__(self, context, truth: List[Tuple[float, float, float]]):
        from diagnostic_msgs.msg import DiagnosticArray
        from geometry_msgs.msg import WrenchStamped
        from rclpy.node import Node
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from std_msgs.msg import Float64, Header

        from ..nodes.sim_node import SIM_TIME_ORIGIN_NS
        from ..nodes.stream import WARMUP_MESSAGE

        self._warmup_message = WARMUP_MESSAGE
        from ..io.fields import seconds_since, stamp_ns

        self._stamp_ns, self._seconds_since = stamp_ns, seconds_since
        self._origin = SIM_TIME_ORIGIN_NS
        self.record = Record(truth)
        self.node = Node('vib_demo', context=context)
        self._last_reset = 0.0
        self._frequencies: deque = deque()
        self._resets: deque = deque()
        reliable = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
        latched = QoSProfile(
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        self.node.create_subscription(WrenchStamped, 'coupling_torque', self._on_torque, reliable)
        self.node.create_subscription(Float64, 'vibration/ground_truth', self._on_truth, latched)
        #: the estimates' subscriptions (the demo waits until they have matched a publisher)
        self.estimate_subs = [
            self.node.create_subscription(
                Float64, 'vibration/frequency', self._on_frequency, reliable
            ),
            self.node.create_subscription(Header, 'vibration/reset', self._on_reset, reliable),
        ]
        self.node.create_subscription(DiagnosticArray, '/diagnostics', self._on_diagnostics, 10)
        #: node names whose /diagnostics say they estimate (not warming up)
        self.ready: set = set()
        self._warming: set = set()
        #: node name -> the key-values of its last /diagnostics status
        self.values: dict = {}

    def _on_diagnostics(self, msg) -> None:
        for status in msg.status:
            self.values[status.name] = {kv.key: kv.value for kv in status.values}
            if status.message == self._warmup_message:
                if status.name not in self._warming:
                    self._warming.add(status.name)
                    print(
                        f'{status.name}: {status.message}; the demo starts the simulator when '
                        'it is ready',
                        flush=True,
                    )
            else:
                self.ready.add(status.name)

    def _seconds(self, header) -> float:
        return self._seconds_since(self._stamp_ns(header), self._origin)

    def _on_torque(self, msg) -> None:
        self.record.t.append(self._seconds(msg.header))
        self.record.torque.append(msg.wrench.torque.z)

    def _on_truth(self, msg) -> None:
        self.record.heard_truth.append(msg.data)
        print(f'ground truth: f0 = {msg.data:.3f} Hz', flush=True)

    def _on_frequency(self, msg) -> None:
        self._frequencies.append(msg.data)
        self._pair()

    def _on_reset(self, msg) -> None:
        self._resets.append(self._seconds(msg))
        self._pair()

    def _pair(self) -> None:
        """Match the i-th frequency with the i-th reset (published in that order)."""
        while self._frequencies and self._resets:
            f, t = self._frequencies.popleft(), self._resets.popleft()
            rec = self.record
            rec.est_t.append(t)
            rec.est_f.append(f)
            rec.est_conv.append(t - self._last_reset)
            self._last_reset = t
            f0 = rec.truth_at(t)
            print(
                f'[{t:6.2f} s] estimate {f:.4f} Hz   true {f0:.4f} Hz   error '
                f'{(f - f0) / f0 * 100:+6.2f} %   converged in {rec.est_conv[-1]:.3f} s',
                flush=True,
            )

    def status_count(self, node: str, key: str) -> int:
        """A count in ``node``'s last /diagnostics status (0 before one)."""
        return int(float(self.values.get(node, {}).get(key, '0')))

    def hears_estimates(self) -> bool:
        """Whether estimator_node's estimate publishers and this node's subscriptions have matched
        each other (its /diagnostics' ``frequency_subscribers``; the graph is not enough: what is
        published before the match is never heard)."""
        return (
            all(sub.get_publisher_count() >= 1 for sub in self.estimate_subs)
            and self.status_count('/estimator_node', 'frequency_subscribers') >= 1
        )

    def counts(self, topic: str) -> Tuple[int, int]:
        """(publishers, subscribers) of a topic as this node sees them."""
        return self.node.count_publishers(topic), self.node.count_subscribers(topic)


def _start(exe: str, params: List[str], env: dict) -> subprocess.Popen:
    cmd = [str(Path(sys.executable).parent / exe), '--ros-args']
    for p in params:
        cmd += ['-p', p]
    # a demo started from a background job inherits SIGINT ignored: give the nodes the default,
    # so that _stop's SIGINT ends them cleanly
    return subprocess.Popen(
        cmd,
        env=env,
        stdout=subprocess.DEVNULL,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )


def _stop(proc: subprocess.Popen) -> None:
    """SIGINT, wait, then kill."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(STOP_TIMEOUT)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


class Session:
    """The demo's ROS side: a private domain, this process's context, executor and
    :class:`Listener`, and the node subprocesses (stopped, and everything shut down, on exit)."""

    def __init__(self, args: argparse.Namespace, truth: List[Tuple[float, float, float]]):
        import rclpy

        from ..nodes.runner import make_executor

        self.domain = demo_domain(args.domain_id, os.environ.get('ROS_DOMAIN_ID'))
        os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'  # read by rclpy.init below
        self.env = dict(os.environ, ROS_DOMAIN_ID=str(self.domain))
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=self.domain)
        self.executor = make_executor(self.context)
        self.listener = Listener(self.context, truth)
        self.executor.add_node(self.listener.node)
        self.procs: List[subprocess.Popen] = []

    def spin_until(self, predicate, timeout: float) -> bool:
        from ..nodes.runner import spin_until

        return spin_until(self.executor, predicate, timeout)

    def start(
        self, exe: str, params: List[str], ready, timeout: float = STARTUP_TIMEOUT
    ) -> subprocess.Popen:
        """Start a node; wait until ``ready()`` (or its exit); raise RuntimeError if it failed."""
        proc = _start(exe, params, self.env)
        self.procs.append(proc)
        up = self.spin_until(lambda: proc.poll() is not None or ready(), timeout)
        if not up or proc.poll() is not None:
            raise RuntimeError(
                f'{exe} did not come up'
                if proc.poll() is None
                else f'{exe} exited with {proc.returncode}'
            )
        return proc

    def start_estimator(self, params: Sequence[str] = ()) -> subprocess.Popen:
        """Start estimator_node (sim time, ``params`` on top) and wait until its kernels are
        compiled (its /diagnostics stop saying it warms up) and it sees the demo's topics."""
        listener = self.listener
        return self.start(
            'estimator_node',
            ['use_sim_time:=true', *params],
            lambda: (
                '/estimator_node' in listener.ready
                and listener.hears_estimates()
                and listener.counts('coupling_torque')[1]
            ),
            WARMUP_TIMEOUT,
        )

    def start_sim(self, params: List[str]) -> subprocess.Popen:
        sim = _start('sim_node', params, self.env)
        self.procs.append(sim)
        return sim

    def finish_sim(self, sim: subprocess.Popen, duration: float, speed: float) -> None:
        """Spin until sim_node exits; RuntimeError if it failed."""
        self.spin_until(lambda: sim.poll() is not None, STARTUP_TIMEOUT + duration / speed)
        self.spin_until(lambda: False, 0.5)  # the last messages in flight
        if sim.returncode != 0:
            raise RuntimeError(
                'sim_node '
                + (
                    'did not finish in time'
                    if sim.returncode is None
                    else f'exited with {sim.returncode}'
                )
            )

    def close(self) -> None:
        for proc in reversed(self.procs):
            _stop(proc)
        self.executor.shutdown()
        self.listener.node.destroy_node()
        self.context.try_shutdown()
