"""``vib-estimator demo``: the simulated arm and the estimator node live, through three tip masses.

Starts ``sim_node`` (Section 5.5's masses 30 -> 45.55 -> 61.17 g, :func:`arm_model.schedule_5_5`,
sped up, publishing ``/clock``) and ``estimator_node`` (``use_sim_time``) as subprocesses of the
same environment on a private ROS domain, and listens in this process to ``coupling_torque``,
``vibration/ground_truth``, ``vibration/frequency`` and ``vibration/reset``. Each estimate is
printed as it arrives next to the true (Eq. 23) frequency; at the end a Fig. 5/7-like PNG is written
and a table per mass printed. Exit status 0 only if every mass's median error is within 3 %.

Times are the header stamps in simulated time from the simulator's start; the true frequency at a
time comes from the schedule the demo gave the simulator (``vibration/ground_truth`` is checked to
announce each mass). An estimate's time is the stamp of its ``vibration/reset`` (the converging
sample; the node publishes frequency, then reset), and its convergence time the time since the
previous reset (since the start for the first): an estimate the node's quality gate held back also
restarts a segment without a reset message, so this may over-state a few convergence times.
"""
from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import time
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import List, Tuple

import numpy as np

from .sim.arm_model import MASSES_5_5, natural_frequency_hz, schedule_5_5

#: exit criterion: every mass's median |error| within this (%)
MAX_MEDIAN_ERROR_PCT = 3.0
#: seconds allowed for the nodes to start and see each other
STARTUP_TIMEOUT = 30.0
#: a subprocess gets this long to exit on SIGINT before it is killed, s
STOP_TIMEOUT = 5.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('--speed', type=float, default=10.0,
                        help='simulated seconds per wall-clock second (default 10)')
    parser.add_argument('--seconds-per-mass', type=float, default=8.0,
                        help='simulated seconds spent on each tip mass (default 8)')
    parser.add_argument('--out', default='out/demo.png', help='figure path (default out/demo.png)')
    parser.add_argument('--domain-id', type=int, default=None,
                        help='ROS domain of the demo (default: 120 + pid %% 100)')


@dataclass
class Record:
    """What the demo heard, in seconds of simulated time (the simulator's stamps from its origin).

    ``truth`` is the schedule's (t_start, t_end, f0 of Eq. 23) per mass; ``heard_truth`` the values
    received on ``vibration/ground_truth``.
    """

    truth: List[Tuple[float, float, float]]
    heard_truth: List[float] = field(default_factory=list)
    t: List[float] = field(default_factory=list)           # torque samples
    torque: List[float] = field(default_factory=list)
    est_t: List[float] = field(default_factory=list)
    est_f: List[float] = field(default_factory=list)
    est_conv: List[float] = field(default_factory=list)

    def truth_at(self, t: float) -> float:
        """The true frequency at time t."""
        return next((f for t0, t1, f in self.truth if t < t1), self.truth[-1][2])


def mass_g(f0: float) -> float:
    """The tip mass of Table 1's bar that has Eq. 23 frequency f0, g."""
    return 1e3 * natural_frequency_hz(1.0) ** 2 / f0 ** 2


def summarise(rec: Record) -> Tuple[List[str], bool]:
    """Table rows per mass and whether every mass's median error is within 3 %.

    Bias and spread are the mean and the standard deviation of (estimate - f0), in Hz (the
    decomposition of Table 2); the convergence time is in periods of f0.
    """
    t = np.asarray(rec.est_t)
    f = np.asarray(rec.est_f)
    conv = np.asarray(rec.est_conv)
    rows = [f'{"mass g":>7} {"f0 Hz":>6} {"n":>3} {"median err %":>12} {"bias Hz":>8} '
            f'{"spread Hz":>9} {"conv. periods":>13}']
    ok = True
    for t0, t1, f0 in rec.truth:
        sel = (t >= t0) & (t < t1)
        if not sel.any():
            rows.append(f'{mass_g(f0):7.2f} {f0:6.3f} {0:3d}   no estimate')
            ok = False
            continue
        median = float(np.median((f[sel] - f0) / f0 * 100))
        ok &= abs(median) <= MAX_MEDIAN_ERROR_PCT
        rows.append(f'{mass_g(f0):7.2f} {f0:6.3f} {sel.sum():3d} {median:12.2f} '
                    f'{np.mean(f[sel] - f0):8.4f} {np.std(f[sel] - f0):9.4f} '
                    f'{np.median(conv[sel] * f0):13.2f}')
    if not all(any(np.isclose(f0, heard) for heard in rec.heard_truth) for *_, f0 in rec.truth):
        rows.append('warning: vibration/ground_truth did not announce every mass')
    return rows, ok


class Listener:
    """The demo's own node: records the four topics into a :class:`Record`, printing estimates."""

    def __init__(self, context, truth: List[Tuple[float, float, float]]):
        from geometry_msgs.msg import WrenchStamped
        from rclpy.node import Node
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from std_msgs.msg import Float64, Header

        from .nodes.sim_node import SIM_TIME_ORIGIN_NS
        from .io.fields import seconds_since, stamp_ns

        self._stamp_ns, self._seconds_since = stamp_ns, seconds_since
        self._origin = SIM_TIME_ORIGIN_NS
        self.record = Record(truth)
        self.node = Node('vib_demo', context=context)
        self._last_reset = 0.0
        self._frequencies: deque = deque()
        self._resets: deque = deque()
        reliable = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
        latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.node.create_subscription(WrenchStamped, 'coupling_torque', self._on_torque,
                                      reliable)
        self.node.create_subscription(Float64, 'vibration/ground_truth', self._on_truth, latched)
        self.node.create_subscription(Float64, 'vibration/frequency', self._on_frequency,
                                      reliable)
        self.node.create_subscription(Header, 'vibration/reset', self._on_reset, reliable)

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
            print(f'[{t:6.2f} s] estimate {f:.4f} Hz   true {f0:.4f} Hz   error '
                  f'{(f - f0) / f0 * 100:+6.2f} %   converged in {rec.est_conv[-1]:.3f} s',
                  flush=True)

    def counts(self, topic: str) -> Tuple[int, int]:
        """(publishers, subscribers) of a topic as this node sees them."""
        return self.node.count_publishers(topic), self.node.count_subscribers(topic)


def _start(exe: str, params: List[str], env: dict) -> subprocess.Popen:
    cmd = [str(Path(sys.executable).parent / exe), '--ros-args']
    for p in params:
        cmd += ['-p', p]
    return subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL)


def _stop(proc: subprocess.Popen) -> None:
    """SIGINT, wait, then kill."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(STOP_TIMEOUT)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def run(args: argparse.Namespace) -> int:
    import rclpy
    from rclpy.executors import ExternalShutdownException

    from .nodes.runner import make_executor, spin_until
    from .analysis.plotting import plot_estimates
    from .nodes.sim_node import schedule_to_array

    if args.speed <= 0 or args.seconds_per_mass <= 2:
        print('error: --speed must be > 0 and --seconds-per-mass > 2', file=sys.stderr)
        return 2
    domain = args.domain_id if args.domain_id is not None else 120 + os.getpid() % 100
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'   # read by rclpy.init below
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain))
    duration = 3 * args.seconds_per_mass
    schedule = schedule_to_array(schedule_5_5(args.seconds_per_mass))
    truth = [(i * args.seconds_per_mass, (i + 1) * args.seconds_per_mass, natural_frequency_hz(m))
             for i, m in enumerate(MASSES_5_5)]
    wall_start = time.monotonic()

    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain)
    executor = make_executor(context)
    listener = Listener(context, truth)
    executor.add_node(listener.node)
    procs: List[subprocess.Popen] = []

    try:
        print(f'demo: ROS domain {domain}, {duration:g} s simulated at {args.speed:g}x, tip masses '
              + ' -> '.join(f'{m * 1e3:g} g' for m in MASSES_5_5), flush=True)
        estimator = _start('estimator_node', ['use_sim_time:=true'], env)
        procs.append(estimator)
        up = spin_until(executor, lambda: estimator.poll() is not None or (
            listener.counts('vibration/frequency')[0] and listener.counts('coupling_torque')[1]),
            STARTUP_TIMEOUT)
        if not up or estimator.poll() is not None:
            print('error: estimator_node did not come up', file=sys.stderr)
            return 1
        sim = _start('sim_node', [f'speed:={float(args.speed)}', f'duration:={float(duration)}',
                                  'publish_clock:=true', 'wait_for_subscribers:=2',
                                  'schedule:=[' + ', '.join(map(repr, schedule)) + ']'], env)
        procs.append(sim)
        spin_until(executor, lambda: sim.poll() is not None,
                   STARTUP_TIMEOUT + duration / args.speed)
        spin_until(executor, lambda: False, 0.5)   # the last messages in flight
        if sim.returncode != 0:
            print('error: sim_node ' + ('did not finish in time' if sim.returncode is None
                                        else f'exited with {sim.returncode}'), file=sys.stderr)
            return 1
    except (KeyboardInterrupt, ExternalShutdownException):
        print('interrupted', file=sys.stderr)
        return 130
    finally:
        for proc in reversed(procs):
            _stop(proc)
        executor.shutdown()
        listener.node.destroy_node()
        context.try_shutdown()

    rec = listener.record
    rows, ok = summarise(rec)
    print('\n' + '\n'.join(rows))
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    plot_estimates(str(out), np.asarray(rec.t), np.asarray(rec.torque), np.asarray(rec.est_t),
                   np.asarray(rec.est_f), np.asarray(rec.est_conv), rec.truth,
                   title=f'Simulated arm, tip masses 30 / 45.55 / 61.17 g ({args.speed:g}x)',
                   ylabel='coupling torque (N m)')
    print(f'\n{len(rec.t)} samples, {len(rec.est_t)} estimates in '
          f'{time.monotonic() - wall_start:.1f} s; figure: {out}')
    print('PASS: every median error within 3 %' if ok
          else 'FAIL: a mass without estimates or with a median error above 3 %')
    return 0 if ok else 1
