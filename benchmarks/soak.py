# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""A soak: the nodes for a long time at speed, with faults on a seeded schedule; prints figures.

    .venv/bin/python benchmarks/soak.py                      # 6 minutes, a fault every 24 s
    .venv/bin/python benchmarks/soak.py --sim-hours 8        # 8 h simulated: 48 min, faults
    make soak                                                # the 6-minute run

What runs (each its own process, as an operator starts them): ``sim_node`` at ``--speed`` (10:
5000 samples/s of stamps in simulated time, ``excitation`` ambient: the arm never at rest) and
``estimator_node`` on it with ``use_sim_time`` and ``excitation`` ambient (``-p`` adds parameters;
its defaults, free decays, on the noise-driven arm: median error 0.8 %, the worst 6 %);
``bag_replayer`` looping ``bags/arm_5_3`` into a second ``estimator_node`` under ``/replay``.
This process watches ``/diagnostics``, ``vibration/frequency`` and ``vibration/ground_truth`` and
injects the faults, in turn from a seeded shuffle of:

* ``stop``: SIGSTOP of estimator_node for 2 s (``--stop-s``), then SIGCONT;
* ``restart``: sim_node stopped (SIGINT) and started again: its time goes back to 1 s;
* ``storm``: 200 parameter sets within a second, every other one invalid (each must be answered,
  the invalid refused, the valid accepted);
* ``calls``: 100 concurrent ``~/self_test`` and ``~/reset`` calls (each must be answered);
* ``burst``: sim_node paused (SIGSTOP) and 5000 messages published at full speed on the input
  topic, their stamps continuing the simulator's: each must be received or counted
  (``received`` + ``samples_missing`` grow by 5000); then sim_node resumes (its stamps go back);
* ``gone``: sim_node stopped for 10 s (SIGINT), then started again.

Measured: estimator_node's RSS every second (growth after the first tenth of the run), each
fault's recovery (steady seconds from its end to the next message taken and to the next estimate
published; the estimator windows of data the node took from one to the other), the
diagnostics' longest silence outside the stops, the counters' identities
(docs/nodes.md#what-the-counters-count) at the end, estimates within 2 % of the simulator's
ground truth outside the fault windows (a fault's window: from its start until the estimator's
window, 30 s of simulated time, has moved past its end and the backlog drained), the
logs' tracebacks, and each node's exit code and time after SIGINT. ``--json`` writes the
figures. Exit 1 when a goal fails (every fault recovered: input again before the next fault and
an estimate within 3 estimator windows of data, 2 and an analysis hop after a stop; identities
hold, every burst message accounted for, every call answered, no traceback, exit 0 within 2 s).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

os.environ.setdefault('ROS_DOMAIN_ID', str(120 + os.getpid() % 80))
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

import rclpy  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue  # noqa: E402
from rcl_interfaces.srv import GetParameters, SetParameters  # noqa: E402
from rclpy.node import Node  # noqa: E402
from rclpy.qos import QoSProfile, ReliabilityPolicy  # noqa: E402
from rosgraph_msgs.msg import Clock as ClockMsg  # noqa: E402
from std_msgs.msg import Float64, Header  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402

from vib_estimator.core.ambient import hop_s  # noqa: E402
from vib_estimator.io.fields import stamp_ns  # noqa: E402
from vib_estimator.nodes.health import identities  # noqa: E402
from vib_estimator.nodes.runner import make_executor  # noqa: E402
from vib_estimator.nodes.sim_node import GROUND_TRUTH_QOS  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
BAG = ROOT / 'bags' / 'arm_5_3'
FAULTS = ('stop', 'restart', 'storm', 'calls', 'burst', 'gone')
#: the estimator's analysis window (ambient_window_s, its default), simulated s
WINDOW_S = 30.0
#: a fault starts only this long (s) before the end of the run, at the latest
FAULT_S = {'stop': 6.0, 'restart': 6.0, 'storm': 6.0, 'calls': 6.0, 'burst': 15.0, 'gone': 16.0}
#: the goals of issue 40
EXIT_WITHIN_S = 2.0
ACCURACY = 0.02
#: seconds of steady time a node is given to show it is alive after a start
START_S = 60.0
#: shaper_node's reference moves every this many seconds (0 and 0.5 rad in turn)
REFERENCE_EVERY_S = 3.0
#: a fault's figures the soak prints in its own words (the others: name and value)
SHOWN = ('kind', 'start', 'end', 'input_s', 'estimate_s', 'windows', 'recovered')
#: a fault is recovered by an estimate within this many estimator windows of data taken after
#: input came again
RECOVERY_WINDOWS = 3.0
#: after a stop of the node, an estimate within this many (one window of data when the stall
#: restarted the estimator; a second for what was taken before the restart point), and the
#: identifier's analysis hop (:func:`hop_s`: its first analysis of a full window comes up to a
#: hop after the window filled; a CI run read 2.10 windows of 30 s, 2 + 5 / 30 allowed)
STALL_WINDOWS = 2.0
#: the simulated seconds an estimate may come after the stream time it was given up at: the
#: node's input queue (5000 samples, 10 s at 500 Hz) and an analysis in flight
LAG_S = 20.0
#: sim_node's sampling rate, Hz (the estimator's sample_rate_hz until its diagnostics say it)
SAMPLE_RATE_HZ = 500.0
#: the hidden soak's RSS limit (issue 40: 20 MB growth; 10 MB after the first 10 min of 8 h)
RSS_GROWTH_MB = 20.0
#: issue 40's goal for hours of simulated operation (``--sim-hours``): RSS growth after the first
#: RSS_AFTER_SIM_S of simulated time (10 minutes)
RSS_GROWTH_LONG_MB = 10.0
RSS_AFTER_SIM_S = 600.0
#: a fault's input is waited for at least this long (s), however dense the schedule, and input
#: that stops again for this long after it came back is deafness (a simulator started again on a
#: loaded machine takes seconds to import and match: not a fault unrecovered)
INPUT_WAIT_S = 24.0
#: a recovery under way when the run ends is waited for this long (s) at most, then judged
RECOVERY_WAIT_S = 180.0
#: the soak's progress line (RSS, load, counters) every this many seconds
PROGRESS_EVERY_S = 300.0


def stall_windows(window_s: float) -> float:
    """The estimator windows of stream an estimate may come after a stop of the node
    (:data:`STALL_WINDOWS` and a hop of the identifier's analysis of a ``window_s`` window)."""
    return STALL_WINDOWS + hop_s(window_s) / window_s


def executable(name: str) -> str:
    """The console script next to this interpreter (a venv), else on the PATH."""
    here = Path(sys.executable).parent / name
    return str(here) if here.exists() else name


class Proc:
    """A node's process, its stderr in a file (tracebacks are looked for there)."""

    def __init__(self, name: str, args, logs: Path):
        self.name = name
        self.args = [executable(args[0]), *args[1:]]
        self.logs = logs
        self.runs = 0
        self.p = None
        self.rss = []  # (steady s since the soak's start, MB, run)
        self.start()

    def start(self) -> None:
        self.runs += 1
        err = open(self.logs / f'{self.name}.{self.runs}.err', 'w')
        self.p = subprocess.Popen(self.args, stdout=err, stderr=err)

    def signal(self, sig) -> None:
        self.p.send_signal(sig)

    def stop(self) -> tuple:
        """SIGINT; (exit code, seconds to exit) -- code None if killed after 10 s."""
        t0 = time.monotonic()
        self.p.send_signal(signal.SIGINT)
        try:
            code = self.p.wait(10.0)
        except subprocess.TimeoutExpired:
            self.p.kill()
            self.p.wait()
            code = None
        return code, time.monotonic() - t0

    def rss_mb(self) -> float:
        try:
            text = Path(f'/proc/{self.p.pid}/status').read_text()
        except OSError:
            return math.nan
        kb = next(int(line.split()[1]) for line in text.splitlines() if line.startswith('VmRSS'))
        return kb / 1024.0

    def rss_growth_mb(self, after: float) -> float:
        """RSS growth of its last run from its first sample at or after ``after`` (steady s
        since the soak's start) to its largest."""
        run = [mb for t, mb, k in self.rss if k == self.runs and t >= after and mb == mb]
        return max(run) - run[0] if run else math.nan

    def tracebacks(self) -> int:
        return sum(
            path.read_text(errors='replace').count('Traceback')
            for path in self.logs.glob(f'{self.name}.*.err')
        )


class Diagnostics(Node):
    """/diagnostics as they arrive, each stamped on reception: spun in a thread of its own, so
    that what the soak's main thread does (a stopped node waited for, a burst published) never
    delays a reception (a silence is the nodes', not the soak's)."""

    def __init__(self):
        super().__init__('soak_diagnostics')
        self.rows = {}  # node name -> [(steady s, level, message, values)]
        self.create_subscription(DiagnosticArray, '/diagnostics', self._on_diag, 100)
        self.executor_ = make_executor()
        self.executor_.add_node(self)
        self._thread = threading.Thread(target=self._spin, name='soak diagnostics', daemon=True)
        self._stop = False
        self._thread.start()

    def _spin(self) -> None:
        while not self._stop and rclpy.ok():
            self.executor_.spin_once(timeout_sec=0.05)

    def _on_diag(self, msg) -> None:
        now = time.monotonic()
        for s in msg.status:
            values = {kv.key: kv.value for kv in s.values}
            self.rows.setdefault(s.name, []).append((now, s.level[0], s.message, values))

    def close(self) -> None:
        self._stop = True
        self._thread.join(5.0)
        self.executor_.shutdown()
        self.destroy_node()


class Watch(Node):
    """The soak's eyes and hands: estimates, truth; faults' service calls (diagnostics:
    :class:`Diagnostics`)."""

    def __init__(self):
        super().__init__('soak_watch')
        self.listener = Diagnostics()
        self.diag = self.listener.rows
        #: shaper_node's reference: a move every REFERENCE_EVERY_S (reliable, as a controller's)
        self.reference = self.create_publisher(Float64, 'reference', 10)
        self.references = 0
        self.reference_at = -math.inf
        self.reference_matched = math.inf
        #: the replayed bag's input as the replay estimator gets it: messages, loops (stamps back)
        self.replayed = {'messages': 0, 'loops': 0, 'last': -1}
        self.create_subscription(
            WrenchStamped,
            '/replay/coupling_torque',
            self._on_replayed,
            QoSProfile(depth=1000, reliability=ReliabilityPolicy.BEST_EFFORT),
        )
        self.estimates = {'/': [], '/replay': []}  # [(steady s, Hz)]
        self.truth = []  # [(steady s, Hz)]
        #: each estimate's sample stamp (vibration/reset: the sample that completed it), the
        #: stream time a recovery is measured in
        self.resets = []  # [(steady s, stamp ns)]
        self.create_subscription(
            Header,
            'vibration/reset',
            lambda m: self.resets.append((time.monotonic(), stamp_ns(m))),
            100,
        )
        #: the simulator's clock (sim_node publishes /clock with each batch of samples): the
        #: latest, and the first received since :meth:`mark_clock` (or since it went back: a
        #: simulator started again), from which a recovery is measured
        self.clock_ns = None
        self.clock_first = None
        self.create_subscription(
            ClockMsg,
            '/clock',
            self._on_clock,
            QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT),
        )
        for ns in self.estimates:
            self.create_subscription(
                Float64,
                f'{ns.rstrip("/")}/vibration/frequency',
                lambda m, ns=ns: self.estimates[ns].append((time.monotonic(), m.data)),
                100,
            )
        self.create_subscription(
            Float64,
            'vibration/ground_truth',
            lambda m: self.truth.append((time.monotonic(), m.data)),
            GROUND_TRUTH_QOS,
        )
        # deep histories: 200 answers at once must not overwrite each other in this client
        deep = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
        self.set_params = self.create_client(
            SetParameters, '/estimator_node/set_parameters', qos_profile=deep
        )
        self.get_params = self.create_client(GetParameters, '/estimator_node/get_parameters')
        self.triggers = {
            name: self.create_client(Trigger, f'/estimator_node/{name}', qos_profile=deep)
            for name in ('self_test', 'reset')
        }

    def _on_clock(self, msg) -> None:
        ns = msg.clock.sec * 10**9 + msg.clock.nanosec
        if self.clock_first is None or (self.clock_ns is not None and ns < self.clock_ns - 10**9):
            self.clock_first = ns  # (a clock gone back: the time base the node now estimates in)
        self.clock_ns = ns

    def mark_clock(self) -> None:
        """Take the next /clock received as the reference (:attr:`clock_first`)."""
        self.clock_first = None

    def _on_replayed(self, msg) -> None:
        r = self.replayed
        stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
        r['messages'] += 1
        r['loops'] += stamp < r['last']
        r['last'] = stamp
        if r.get('offset') is None:
            # what the replay estimator will be held to: the messages after its first one (the
            # replayer starts once a subscriber, maybe this one, is matched; the estimator may
            # come later): those seen here when its diagnostics first show one received, less
            # those it had received (lenient by the few in flight at that moment)
            c = self.counters('/replay/estimator_node')
            if c.get('received', 0) > 0:
                r['offset'] = r['messages'] - c['received']

    def counters(self, name='/estimator_node') -> dict:
        rows = self.diag.get(name)
        if not rows:
            return {}
        return {k: int(v) for k, v in rows[-1][3].items() if v.lstrip('-').isdigit()}

    def truth_at(self, t: float) -> float:
        before = [f for at, f in self.truth if at <= t]
        return before[-1] if before else math.nan


def param(name: str, value: float) -> Parameter:
    return Parameter(
        name=name, value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=value)
    )


class Soak:
    def __init__(self, args, logs: Path):
        self.args = args
        self.logs = logs
        self.rng = random.Random(args.seed)
        self.seed = 0
        speed = f'speed:={args.speed}'
        excitation = f'excitation:={args.excitation}'
        self.sim_args = ['sim_node', '--ros-args', '-p', speed, '-p', excitation, *args.sim_args]
        self.est = Proc(
            'estimator_node',
            ['estimator_node', '--ros-args', '-p', 'use_sim_time:=true', *args.estimator_args],
            logs,
        )
        self.sim = self._sim()
        self.procs = [self.est, self.sim]
        if args.replayer:
            self.replay_est = Proc(
                'replay_estimator',
                ['estimator_node', '--ros-args', '-r', '__ns:=/replay'],
                logs,
            )
            self.replayer = Proc(
                'bag_replayer',
                [
                    'bag_replayer',
                    '--ros-args',
                    '-p',
                    f'bag:={BAG}',
                    '-p',
                    'loop:=true',
                    '-p',
                    'topics:=[/coupling_torque]',
                    '-p',
                    "remap:=['/coupling_torque:=/replay/coupling_torque']",
                ],
                logs,
            )
            self.procs += [self.replay_est, self.replayer]
        if args.shaper:
            # on the estimator's vibration/frequency, the soak's reference; in the simulated time
            # (on the wall clock its ZVD impulses, 0.38 s apart for 1.33 Hz, were 5 periods of the
            # simulated arm: each reference move an unshaped step, every 30 simulated s)
            self.shaper = Proc(
                'shaper_node', ['shaper_node', '--ros-args', '-p', 'use_sim_time:=true'], logs
            )
            self.procs.append(self.shaper)
        rclpy.init(args=[])  # (not sys.argv: the soak's own -p would read as remap rules)
        self.watch = Watch()
        self.ex = make_executor()
        self.ex.add_node(self.watch)
        self.rss = []  # (steady s since start, MB)
        self.load = []  # (steady s since start, the 1-min load average)
        self.progress_at = 0.0
        self.faults = []  # dicts
        self.problems = []

    def _sim(self, proc=None) -> Proc:
        self.seed += 1
        args = self.sim_args + ['-p', f'seed:={self.seed}']
        if proc is None:
            return Proc('sim_node', args, self.logs)
        proc.args = [executable(args[0]), *args[1:]]
        proc.start()
        return proc

    # ---- helpers ---------------------------------------------------------------------------
    def spin(self, seconds: float, until=lambda: False) -> bool:
        """Spin (and sample RSS) for ``seconds`` or until ``until()``."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            if until():
                return True
            self.ex.spin_once(timeout_sec=0.05)
            self._sample_rss()
        return until()

    def _sample_rss(self) -> None:
        now = time.monotonic() - self.t0
        if not self.rss or now - self.rss[-1][0] >= 1.0:
            self.rss.append((now, self.est.rss_mb()))
            self.load.append((now, os.getloadavg()[0]))
            if now - self.progress_at >= PROGRESS_EVERY_S:
                self._progress(now)
            for proc in self.procs:
                proc.rss.append((now, proc.rss_mb(), proc.runs))
            w = self.watch
            if (
                self.args.shaper
                and now - w.reference_at >= REFERENCE_EVERY_S
                and self._reference_matched(now)  # sent: taken by the shaper
            ):
                w.reference_at = now
                self.watch.reference.publish(Float64(data=0.5 * (self.watch.references % 2)))
                self.watch.references += 1

    def _reference_matched(self, now: float) -> bool:
        """Whether the shaper has been matched on the reference for a second (discovery ends at
        either side in turn: a message sent at the first match may find no reader yet)."""
        w = self.watch
        if w.reference.get_subscription_count() == 0:
            w.reference_matched = math.inf
        elif w.reference_matched == math.inf:
            w.reference_matched = now
        return now - w.reference_matched >= 1.0

    def _progress(self, now: float) -> None:
        """A line in the log: the run's time (wall and simulated), each node's RSS, the load, the
        estimator's counters."""
        self.progress_at = now
        c = self.watch.counters()
        print(
            f'{now:7.1f} s  (simulated {now * self.args.speed / 3600:.2f} h)  RSS MB: '
            + ', '.join(f'{p.name} {p.rss[-1][1]:.1f}' for p in self.procs if p.rss)
            + f'; load {self.load[-1][1]:.2f}; received {c.get("received")}, samples_missing '
            f'{c.get("samples_missing")}, faults {len(self.faults)}',
            flush=True,
        )

    def taken(self) -> int:
        c = self.watch.counters()
        return c.get('received', 0) + c.get('skipped_joint_missing', 0)

    # ---- faults ----------------------------------------------------------------------------
    def fault_stop(self, f) -> None:
        self.est.signal(signal.SIGSTOP)
        time.sleep(self.args.stop_s)  # the node is stopped: nothing to spin for it
        self.est.signal(signal.SIGCONT)

    def fault_restart(self, f) -> None:
        f['sim_exit'] = self.sim.stop()[0]
        self._sim(self.sim)

    def fault_gone(self, f) -> None:
        f['sim_exit'] = self.sim.stop()[0]
        self.spin(10.0)
        self._sim(self.sim)

    def fault_storm(self, f) -> None:
        client = self.watch.set_params
        if not client.wait_for_service(timeout_sec=5.0):
            self.problems.append('storm: set_parameters not available')
            return
        futures = []
        t0 = time.monotonic()
        for i in range(200):
            valid = i % 2 == 0
            value = 0.5 if valid else (-1.0 if i % 4 == 1 else math.nan)  # max_gap
            futures.append(
                (
                    valid,
                    client.call_async(SetParameters.Request(parameters=[param('max_gap', value)])),
                )
            )
            self.ex.spin_once(timeout_sec=0)
            delay = t0 + (i + 1) / 200 - time.monotonic()
            if delay > 0:
                self.spin(delay)
        self.spin(30.0, lambda: all(fu.done() for _, fu in futures))
        answered = [fu for _, fu in futures if fu.done()]
        wrong = sum(
            fu.result().results[0].successful != valid for valid, fu in futures if fu.done()
        )
        f.update(calls=len(futures), answered=len(answered), wrong_verdicts=wrong)
        if len(answered) != len(futures) or wrong:
            self.problems.append(f'storm: {len(answered)}/{len(futures)} answered, {wrong} wrong')

    def fault_calls(self, f) -> None:
        clients = self.watch.triggers
        if not all(c.wait_for_service(timeout_sec=5.0) for c in clients.values()):
            self.problems.append('calls: services not available')
            return
        futures = [
            clients['self_test' if i % 2 else 'reset'].call_async(Trigger.Request())
            for i in range(100)
        ]
        self.spin(60.0, lambda: all(fu.done() for fu in futures))
        answered = sum(fu.done() for fu in futures)
        f.update(calls=100, answered=answered)
        if answered != 100:
            self.problems.append(f'calls: {answered}/100 answered')

    def fault_burst(self, f) -> None:
        stamps = []
        sub = self.watch.create_subscription(
            WrenchStamped,
            'coupling_torque',
            lambda m: stamps.append(m.header.stamp.sec * 10**9 + m.header.stamp.nanosec),
            QoSProfile(depth=100, reliability=ReliabilityPolicy.BEST_EFFORT),
        )
        # made for the burst only, and matched while the simulator still publishes: a publisher
        # matched but silent for 3 s wakes the node's watchdog (matching took seconds on a loaded
        # machine: the node re-created its input once, a run of the suite at load 7)
        reliable = QoSProfile(depth=10000, reliability=ReliabilityPolicy.RELIABLE)
        burster = self.watch.create_publisher(WrenchStamped, 'coupling_torque', reliable)
        self.spin(5.0, lambda: len(stamps) > 50 and burster.get_subscription_count() >= 2)
        self.sim.signal(signal.SIGSTOP)
        stopped = time.monotonic()
        self.spin(1.0)
        self.watch.destroy_subscription(sub)
        if len(stamps) < 50:
            self.sim.signal(signal.SIGCONT)
            self.watch.destroy_publisher(burster)
            self.problems.append('burst: no input seen to continue')
            return
        period = round((stamps[-1] - stamps[-51]) / 50)
        before = self.watch.counters()
        self.spin(3.0, lambda: self.taken() >= before.get('received', 0) and self._quiet(before))
        before = self.watch.counters()
        msg = WrenchStamped()
        msg.header.frame_id = 'arm_base'
        t0 = time.monotonic()
        last = max(stamps)
        for k in range(1, 5001):
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(last + k * period, 10**9)
            msg.wrench.torque.z = math.sin(k * 0.02)
            burster.publish(msg)
        f['burst_rate'] = 5000 / (time.monotonic() - t0)
        # one more after a pause closes the burst (a loss at its end is a gap before it)
        self.spin(1.5)
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(last + 5001 * period, 10**9)
        burster.publish(msg)
        closed = time.monotonic()

        def accounted():
            c = self.watch.counters()
            return (c.get('received', 0) + c.get('samples_missing', 0)) - (
                before.get('received', 0) + before.get('samples_missing', 0)
            )

        self.spin(5.0, lambda: accounted() >= 5001)
        c = self.watch.counters()
        f.update(
            received=c.get('received', 0) - before.get('received', 0),
            missing=c.get('samples_missing', 0) - before.get('samples_missing', 0),
            transport=c.get('lost_in_transport', 0) - before.get('lost_in_transport', 0),
        )
        # nothing lost uncounted: at least the burst is received or counted (more is the
        # simulator's samples still in flight when it was stopped: a fresh-clone CI run on the
        # Jazzy set read 5044 = 4012 received + 1032 missing)
        if accounted() < 5001:
            self.problems.append(f'burst: {accounted()} of 5001 received or counted')
        self.watch.destroy_publisher(burster)
        self.sim.signal(signal.SIGCONT)
        # the node's silences, a stopped publisher matched: before the burst and after it (each
        # past the watchdog's wait re-creates the input subscription, as it should)
        f['silences_s'] = [t0 - stopped, time.monotonic() - closed]

    def _others(self, settled: dict) -> dict:
        """The replayed bag and the shaper: what each node took of what was sent to it, the
        longest silence of its diagnostics, and (the shaper) how soon after each fault it took an
        estimate again."""
        out = {'unaccounted': []}
        if self.args.replayer:
            c = settled['replay/estimator_node']
            sent = self.watch.replayed['messages'] - (self.watch.replayed.get('offset') or 0)
            took = c.get('received', 0) + c.get('samples_missing', 0)
            out['replay'] = dict(
                seen_by_soak=self.watch.replayed['messages'],
                sent_after_its_first=sent,
                loops=self.watch.replayed['loops'],
                received=c.get('received'),
                samples_missing=c.get('samples_missing'),
                time_jump_resets=c.get('time_jump_resets'),
                estimates=len(self.watch.estimates['/replay']),
                silence_s=self._silence('/replay/estimator_node'),
            )
            if took < sent:
                out['unaccounted'].append(f'replay: {took} received or counted of {sent} seen')
        if self.args.shaper:
            c = settled['shaper_node']
            published = len(self.watch.estimates['/'])
            rows = self.watch.diag.get('/shaper_node', [])
            taken_at = []  # steady s at which frequency_estimates grew
            last = None
            for at, _, _, values in rows:
                n = int(values.get('frequency_estimates', 0))
                if last is not None and n > last:
                    taken_at.append(at)
                last = n
            resumed = [
                min((t for t in taken_at if t > f['end']), default=math.inf) - f['end']
                for f in self.faults
            ]
            out['shaper'] = dict(
                references_sent=self.watch.references,
                references=c.get('references'),
                estimates_published=published,
                frequency_estimates=c.get('frequency_estimates'),
                estimates_ignored=c.get('estimates_ignored'),
                commands_published=c.get('commands_published'),
                estimate_resumed_s=max(resumed, default=math.nan),
                silence_s=self._silence('/shaper_node'),
            )
            if c.get('references', 0) + c.get('references_skipped', 0) < self.watch.references:
                out['unaccounted'].append(
                    f'shaper: {c.get("references")} references of {self.watch.references}'
                )
            if c.get('frequency_estimates', 0) + c.get('estimates_ignored', 0) < published:
                out['unaccounted'].append(
                    f'shaper: {c.get("frequency_estimates")} estimates of {published} published'
                )
        return out

    @staticmethod
    def _per_minute(samples) -> list:
        """The first of ``samples`` ((steady s, value)) in each minute of the run."""
        out, minute = [], -1
        for t, x in samples:
            if int(t // 60) > minute:
                minute = int(t // 60)
                out.append(round(x, 2))
        return out

    def _silence(self, name: str) -> float:
        """The longest interval between two diagnostics of ``name`` (s)."""
        stamps = [row[0] for row in self.watch.diag.get(name, [])]
        return float(max(np.diff(stamps))) if len(stamps) > 1 else math.nan

    def _quiet(self, before) -> bool:
        return self.watch.counters().get('received', 0) == before.get('received', 0)

    # ---- the run ---------------------------------------------------------------------------
    def run(self) -> dict:
        self.t0 = time.monotonic()
        if not self.spin(START_S, lambda: self.taken() > 1000 and self.watch.estimates['/']):
            self.problems.append('no estimate within the start-up time')
        order = []
        end = self.t0 + self.args.minutes * 60
        next_at = time.monotonic() + self.args.fault_every
        count = self.args.count
        while len(self.faults) < count if count else time.monotonic() + 5 < end:
            if not order:
                order = list(self.args.faults)
                self.rng.shuffle(order)
            self.spin(max(0.0, next_at - time.monotonic()))
            kind = order.pop()
            longer = max(0.0, self.args.stop_s - 2.0) if kind == 'stop' else 0.0
            # it would not end (and a node restarted then stopped in its first second dies of
            # the KeyboardInterrupt)
            if time.monotonic() + FAULT_S[kind] + longer > end:
                if count:
                    self.problems.append(f'{len(self.faults)} faults of {count} within the run')
                break
            f = {'kind': kind, 'start': time.monotonic()}
            taken0 = self.taken()
            getattr(self, f'fault_{kind}')(f)
            f['end'] = time.monotonic()
            n_est = len(self.watch.resets)
            self.watch.mark_clock()  # the stream time the recovery is measured from
            next_at = f['end'] + self.args.fault_every
            # input waited for until the next fault, at least INPUT_WAIT_S (a dense schedule:
            # the next fault waits for it)
            wait = max(self.args.fault_every, INPUT_WAIT_S)
            limit = min(f['end'] + wait, end) - time.monotonic()
            got = self.spin(limit, lambda: self.taken() > taken0 + 100)
            f['input_s'] = time.monotonic() - f['end'] if got else math.nan
            # then an estimate of the data after the fault, measured in the stream's time (the
            # simulator's clock at the fault's end, or its new origin after a restart, to the
            # stamp of the sample that completed the estimate): waited for until the simulator
            # is RECOVERY_WINDOWS estimator windows (and LAG_S for the node's queue) past it,
            # not a steady time nor a count of samples (a loaded machine slows the simulator
            # and the node alike; the node drains a backlog after a stall)
            f['window_s'] = self.node_window_s()
            window_ns = f['window_s'] * 1e9
            flowing = [self.taken(), time.monotonic()]  # the last count taken, and when it grew

            def recovery():
                """(steady s of its arrival, windows of stream) of the first estimate published
                since the fault's end of the data after it, or None. An estimate stamped after
                the simulator's clock is of an earlier time base (a restarted simulator)."""
                w = self.watch
                ref, now = w.clock_first, w.clock_ns
                if ref is None:
                    return None
                for at, stamp in w.resets[n_est:]:
                    if ref - window_ns <= stamp <= now + 1e9:
                        return at, max(0.0, stamp - ref) / window_ns
                return None

            def gave_up():
                # the stream well past the windows without an estimate, or the input gone again
                # for a fault's spacing (deaf after a few messages)
                taken, w = self.taken(), self.watch
                if taken > flowing[0]:
                    flowing[:] = [taken, time.monotonic()]
                past = w.clock_first is not None and w.clock_ns - w.clock_first > (
                    RECOVERY_WINDOWS * window_ns + LAG_S * 1e9
                )
                return past or time.monotonic() - flowing[1] > wait

            # (the end of the run does not cut a recovery short: it is judged, within
            # RECOVERY_WAIT_S at most)
            self.spin(
                (max(end, f['end'] + RECOVERY_WAIT_S) if got else min(next_at, end))
                - time.monotonic(),
                lambda: recovery() is not None or gave_up(),
            )
            found = recovery()
            f['estimate_s'] = found[0] - f['end'] if found else math.nan
            # estimator windows of stream from the fault's end to the estimate's sample
            f['windows'] = found[1] if found else math.nan
            # a fault whose recovery the end of the run cut short is not judged (None)
            if found:
                f['recovered'] = found[1] <= RECOVERY_WINDOWS
            elif f['input_s'] != f['input_s']:
                f['recovered'] = False if f['end'] + wait < end else None
            else:
                f['recovered'] = False if gave_up() else None
                if time.monotonic() - flowing[1] > wait:
                    f['deaf'] = True  # input again for a moment, then none
            next_at = max(next_at, time.monotonic())
            self.faults.append(f)
            print(
                f'{f["start"] - self.t0:7.1f} s  {kind:8s} input after {f["input_s"]:5.2f} s, '
                f'estimate after {f["estimate_s"]:5.2f} s ({f["windows"]:.2f} windows of stream)'
                + ''.join(
                    f', {k} {f[k]:.0f}' if isinstance(f[k], float) else f', {k} {f[k]}'
                    for k in f
                    if k not in SHOWN
                ),
                flush=True,
            )
        self.spin(self.args.fault_every if count else max(0.0, end - time.monotonic()))
        return self.finish()

    def window_samples(self) -> float:
        """The samples of one estimator window: :meth:`window_s` at the input's rate (the
        estimator's ``sample_rate_hz``, else the simulator's 500 Hz)."""
        rows = self.watch.diag.get('/estimator_node') or [(0, 0, '', {})]
        try:
            rate = float(rows[-1][3].get('sample_rate_hz', 'nan'))
        except ValueError:
            rate = math.nan
        return self.window_s() * (rate if rate > 0 else SAMPLE_RATE_HZ)

    def node_window_s(self) -> float:
        """The window the estimator runs now: its ``ambient_window_s`` under ``excitation``
        ambient or auto (the node's default decides them), else :meth:`window_s`."""
        client = self.watch.get_params
        future = client.call_async(GetParameters.Request(names=['excitation', 'ambient_window_s']))
        if not self.spin(5.0, future.done):
            return self.window_s()
        excitation, window = future.result().values
        if excitation.string_value in ('ambient', 'auto') and window.double_value > 0:
            return window.double_value
        return self.window_s()

    def window_s(self) -> float:
        """The estimator's analysis window, simulated s (``-p ambient_window_s:=``, else its
        default)."""
        given = [a.split(':=')[1] for a in self.args.estimator_args if 'ambient_window_s:=' in a]
        return float(given[-1]) if given else WINDOW_S

    def finish(self) -> dict:
        figures = {'faults': self.faults}
        exits = {}
        # no reference after this: one sent in the last second before the shaper's counters are
        # read below was not in them yet ('shaper: 118 references of 119', ~1 run in 3)
        self.watch.reference_at = math.inf
        # the sources first (sim_node, bag_replayer); the nodes they feed publish what they
        # took, then their counters are read and they are stopped
        sources = [p for p in self.procs if p.name in ('sim_node', 'bag_replayer')]
        for proc in sources:
            code, seconds = proc.stop()
            exits[proc.name] = (code, round(seconds, 2))
        self.spin(3.0)
        final = self.watch.counters()
        settled = {
            n: self.watch.counters(f'/{n}') for n in ('replay/estimator_node', 'shaper_node')
        }
        for proc in self.procs:
            if proc not in sources:
                code, seconds = proc.stop()
                exits[proc.name] = (code, round(seconds, 2))
        self.spin(0.5)
        # the counters
        ident = identities(final)
        # accuracy outside the fault windows
        # a fault's window: from its start until the estimator's window has moved past its end
        # and the backlog drained (an estimate of samples the fault touched: a burst's are not the
        # arm's); a fault not recovered, to the end
        window = WINDOW_S / self.args.speed
        windows = [
            (
                f['start'],
                f['end'] + window + (f['input_s'] if f['input_s'] == f['input_s'] else 0.0)
                if f['recovered'] is not False
                else math.inf,
            )
            for f in self.faults
        ]
        errors = []
        for at, hz in self.watch.estimates['/']:
            if any(a <= at <= b for a, b in windows):
                continue
            truth = self.watch.truth_at(at)
            if truth == truth:
                errors.append(abs(hz / truth - 1))
        errors.sort()
        # RSS after the first tenth
        length = time.monotonic() - self.t0
        tenth = 0.1 * length
        after = [mb for t, mb in self.rss if t >= tenth and mb == mb]
        rss_growth = (max(after) - after[0]) if after else math.nan
        # (a node restarted by the faults, sim_node, has no long life to measure)
        growth = {p.name: round(p.rss_growth_mb(tenth), 1) for p in self.procs if p.runs == 1}
        # hours of simulated operation: the goal's, after the first 10 simulated minutes (and, as
        # a figure, after the first 10 wall-clock minutes)
        long_growth = {}
        if self.args.sim_hours:
            for label, after in (
                ('after_10_simulated_min', RSS_AFTER_SIM_S / self.args.speed),
                ('after_10_wall_min', 600.0),
            ):
                long_growth[label] = {
                    p.name: round(p.rss_growth_mb(after), 1) for p in self.procs if p.runs == 1
                }
        loads = sorted(x for _, x in self.load)
        spacing = np.diff([f['start'] for f in self.faults])
        rate = self.window_samples() / self.window_s()
        peaks = {
            p.name: round(max((mb for _, mb, _ in p.rss if mb == mb), default=0), 1)
            for p in self.procs
        }
        # what the replay estimator and the shaper took of what was sent to them
        others = self._others(settled)
        # diagnostics silences outside the stops
        stamps = [row[0] for row in self.watch.diag.get('/estimator_node', [])]
        stops = [(f['start'], f['end'] + 1.5) for f in self.faults if f['kind'] == 'stop']
        silences = [
            (b - a, a - self.t0)
            for a, b in zip(stamps, stamps[1:])
            if not any(s <= b and a <= e for s, e in stops)
        ]
        # when the node re-created its input subscription (the diagnostics' counter rose): s
        # since the start, and the fault then running or last ended (a watchdog's re-creation
        # is explained by a silence of the input, the fault's or not)
        rows = self.watch.diag.get('/estimator_node', [])
        counts = [(row[0], row[3].get('input_resubscribed', '0')) for row in rows]
        counts = [(at, int(v) if v.isdigit() else 0) for at, v in counts]
        resubscribed = []
        for (_, a), (at, b) in zip(counts, counts[1:]):
            if b > a:
                last = [f for f in self.faults if f['start'] <= at]
                since = f'{last[-1]["kind"]} +{at - last[-1]["start"]:.1f} s' if last else '-'
                resubscribed.append((round(at - self.t0, 1), since))
        # the input's sampling rate each status gave (what the self-test and the band's Nyquist
        # check read): {value to 3 digits: statuses}
        rates: dict = {}
        for row in rows:
            try:
                rate = float(row[3].get('sample_rate_hz', 'nan'))
            except ValueError:
                rate = math.nan
            if rate == rate:
                key = f'{rate:.3g}'
                rates[key] = rates.get(key, 0) + 1
        figures.update(
            counters=final,
            resubscribed_at=resubscribed,
            sample_rates=dict(sorted(rates.items(), key=lambda kv: -kv[1])),
            identities=ident,
            estimates=len(self.watch.estimates['/']),
            replay_estimates=len(self.watch.estimates['/replay']),
            accuracy_n=len(errors),
            accuracy_median=errors[len(errors) // 2] if errors else math.nan,
            accuracy_max=errors[-1] if errors else math.nan,
            within_2pct=sum(e <= ACCURACY for e in errors) / len(errors) if errors else math.nan,
            rss_first_mb=self.rss[0][1] if self.rss else math.nan,
            rss_last_mb=next((mb for _, mb in reversed(self.rss) if mb == mb), math.nan),
            rss_growth_after_first_tenth_mb=rss_growth,
            rss_growth_mb=growth,
            rss_growth_long_mb=long_growth,
            # estimator_node's RSS every 10 s (steady s since the start, MB): when it grew
            rss_every_10s=[(round(t), round(mb, 1)) for t, mb in self.rss[::10]],
            load=dict(
                min=loads[0] if loads else math.nan,
                median=loads[len(loads) // 2] if loads else math.nan,
                max=loads[-1] if loads else math.nan,
                per_minute=self._per_minute(self.load),
            ),
            wall_s=time.monotonic() - self.t0,
            simulated_h_nominal=(time.monotonic() - self.t0) * self.args.speed / 3600,
            simulated_h_taken=(final.get('received', 0) + final.get('samples_missing', 0))
            / rate
            / 3600,
            fault_spacing_s=dict(
                median=float(np.median(spacing)) if len(spacing) else math.nan,
                max=float(spacing.max()) if len(spacing) else math.nan,
            ),
            rss_peak_mb=peaks,
            others=others,
            diagnostics_longest_silence_s=max(silences, default=(math.nan, math.nan)),
            exits=exits,
            tracebacks={p.name: p.tracebacks() for p in self.procs},
            problems=self.problems,
        )
        for name, ok in ident.items():
            if not ok:
                self.problems.append(f'identity fails: {name}')
        for f in self.faults:
            if f['recovered'] is False:
                self.problems.append(
                    f'{f["kind"]} at {f["start"] - self.t0:.0f} s: '
                    + (
                        'no input before the next fault'
                        if f['input_s'] != f['input_s']
                        else 'input again, then none (deaf)'
                        if f.get('deaf')
                        else f'an estimate {f["windows"]:.1f} estimator windows of stream after it'
                        if f['windows'] == f['windows']
                        else f'no estimate within {RECOVERY_WINDOWS:g} estimator windows of stream'
                    )
                )
            elif f['kind'] == 'stop' and f['windows'] > stall_windows(f['window_s']):
                self.problems.append(
                    f'stop at {f["start"] - self.t0:.0f} s: an estimate {f["windows"]:.1f} '
                    'estimator windows of stream after it'
                )
        for name, mb in growth.items():
            # (a shorter run's first tenth is the start-up, the estimator's buffer filling)
            if mb > RSS_GROWTH_MB and length >= 300:
                self.problems.append(f'{name}: RSS grew {mb} MB after the first tenth')
        for name, mb in long_growth.get('after_10_simulated_min', {}).items():
            if mb > RSS_GROWTH_LONG_MB:
                self.problems.append(
                    f'{name}: RSS grew {mb} MB after the first 10 simulated minutes'
                )
        for what in others.get('unaccounted', []):
            self.problems.append(what)
        for name, (code, seconds) in exits.items():
            if code != 0 or seconds > EXIT_WITHIN_S:
                self.problems.append(f'{name}: exit {code} after {seconds} s of SIGINT')
        for name, n in figures['tracebacks'].items():
            if n:
                self.problems.append(f'{name}: {n} tracebacks in its log')
        self.watch.listener.close()
        self.watch.destroy_node()
        rclpy.try_shutdown()
        return figures


def report(fig: dict) -> None:
    print(
        '\nfault     n  recovered  input resumed (s, max)  estimate resumed (s, median / max)'
        '  windows of stream (max)'
    )
    for kind in FAULTS:
        rows = [f for f in fig['faults'] if f['kind'] == kind]
        if not rows:
            continue
        est = sorted(f['estimate_s'] for f in rows if f['recovered'])
        inp = [f['input_s'] for f in rows if f['input_s'] == f['input_s']]
        judged = sum(f['recovered'] is not None for f in rows)
        ok = sum(f['recovered'] is True for f in rows)
        median = est[len(est) // 2] if est else math.nan
        windows = [f['windows'] for f in rows if f['windows'] == f['windows']]
        print(
            f'{kind:8s} {len(rows):2d}  {ok:2d}/{judged:<2d}      '
            f'{max(inp, default=math.nan):6.2f}                  '
            f'{median:6.2f} / {max(est, default=math.nan):6.2f}'
            f'                 {max(windows, default=math.nan):5.2f}'
        )
    judged = [f for f in fig['faults'] if f['windows'] == f['windows']]
    print(
        'recovery in windows of stream from the fault to the estimate (the window the estimator '
        f'ran: {sorted({f["window_s"] for f in judged})} s): within one window and the '
        "identifier's analysis hop "
        f'{sum(f["windows"] <= 1 + hop_s(f["window_s"]) / f["window_s"] for f in judged)} of '
        f'{len(fig["faults"])} faults, within 1.0 {sum(f["windows"] <= 1.0 for f in judged)}'
    )
    c = fig['counters']
    print(
        f'\ncounters: received {c.get("received")}, used {c.get("used")}, samples_missing '
        f'{c.get("samples_missing")} (lost_in_queue {c.get("lost_in_queue")}, missing_in_gaps '
        f'{c.get("missing_in_gaps")}; lost_in_transport {c.get("lost_in_transport")}), '
        f'stamp_jumps {c.get("stamp_jumps")}, time_jump_resets {c.get("time_jump_resets")}, '
        f'input_resubscribed {c.get("input_resubscribed")}'
        + (f' (at s, after: {fig["resubscribed_at"]})' if fig['resubscribed_at'] else '')
    )
    print(
        'identities: '
        + ', '.join(f'{k}: {"holds" if v else "FAILS"}' for k, v in fig['identities'].items())
    )
    print(
        f'estimates: {fig["estimates"]} (replayed bag: {fig["replay_estimates"]}); outside the '
        f'fault windows {fig["accuracy_n"]}: median error {100 * fig["accuracy_median"]:.3f} %, '
        f'max {100 * fig["accuracy_max"]:.3f} %, within 2 %: {100 * fig["within_2pct"]:.1f} %'
    )
    print(
        f'RSS of estimator_node: {fig["rss_first_mb"]:.1f} MB at start, '
        f'{fig["rss_last_mb"]:.1f} MB at the end, growth after the first tenth '
        f'{fig["rss_growth_after_first_tenth_mb"]:.1f} MB'
    )
    print(
        "sample_rate_hz in estimator_node's statuses (Hz: statuses): "
        + ', '.join(f'{k}: {n}' for k, n in fig['sample_rates'].items())
    )
    silence, at = fig['diagnostics_longest_silence_s']
    print(f'diagnostics: longest silence outside the stops {silence:.2f} s (at {at:.0f} s)')
    print(
        'exit after SIGINT: '
        + ', '.join(f'{n} {c} in {s} s' for n, (c, s) in fig['exits'].items())
    )
    print(
        'RSS growth after the first tenth (MB): '
        + ', '.join(f'{n} {mb}' for n, mb in fig['rss_growth_mb'].items())
        + '; peak (MB): '
        + ', '.join(f'{n} {mb}' for n, mb in fig['rss_peak_mb'].items())
    )
    replay = fig['others'].get('replay')
    if replay:
        print(
            f'replayed bag: {replay["loops"]} loops, {replay["seen_by_soak"]} messages seen by '
            f"the soak ({replay['sent_after_its_first']} counted from the replay estimator's "
            'first), '
            f'the replay estimator received {replay["received"]} (missing '
            f'{replay["samples_missing"]}, {replay["time_jump_resets"]} time-jump restarts), '
            f'{replay["estimates"]} estimates, its diagnostics silent {replay["silence_s"]:.2f} s '
            'at most'
        )
    shaper = fig['others'].get('shaper')
    if shaper:
        print(
            f'shaper_node: took {shaper["references"]} of {shaper["references_sent"]} references, '
            f'{shaper["frequency_estimates"]} (+{shaper["estimates_ignored"]} ignored) of '
            f'{shaper["estimates_published"]} estimates published, '
            f'{shaper["commands_published"]} commands; an estimate taken again '
            f'{shaper["estimate_resumed_s"]:.2f} s after a fault at most; its diagnostics silent '
            f'{shaper["silence_s"]:.2f} s at most'
        )
    for label, growth in fig['rss_growth_long_mb'].items():
        print(
            f'RSS growth {label.replace("_", " ")} (MB): '
            + ', '.join(f'{n} {mb}' for n, mb in growth.items())
        )
    load, spacing = fig['load'], fig['fault_spacing_s']
    print(
        f'run: {fig["wall_s"] / 60:.1f} wall minutes, {fig["simulated_h_nominal"]:.2f} h of '
        f'simulated time at the nominal speed, {fig["simulated_h_taken"]:.2f} h of samples taken '
        f'by the estimator (received + missing); {len(fig["faults"])} faults, spacing (start to '
        f'start) median {spacing["median"]:.1f} s, max {spacing["max"]:.1f} s; load average '
        f'(1 min) {load["min"]:.2f} / {load["median"]:.2f} / {load["max"]:.2f} '
        '(min / median / max)'
    )
    print('tracebacks: ' + ', '.join(f'{n} {k}' for n, k in fig['tracebacks'].items()))
    print('problems: ' + ('; '.join(fig['problems']) or 'none'))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--minutes', type=float, default=6.0, help='wall-clock length of the run')
    parser.add_argument(
        '--fault-every',
        type=float,
        default=None,
        help='seconds (wall clock) from the end of a fault to the next one, which also waits for '
        "the first's recovery (default 24; with --sim-hours, one simulated minute: 60 / speed)",
    )
    parser.add_argument(
        '--sim-hours',
        type=float,
        help='hours of simulated operation: a run of HOURS x 3600 / speed wall seconds (sets '
        '--minutes), a fault every simulated minute unless --fault-every, and the goal RSS '
        'growth <= 10 MB after the first 10 simulated minutes',
    )
    parser.add_argument('--speed', type=float, default=10.0, help="sim_node's speed")
    parser.add_argument(
        '--count',
        type=int,
        default=0,
        help='run this many faults, each judged, then end (--minutes is then a limit: a fault '
        'that cannot start before it is a problem); default: faults until --minutes',
    )
    parser.add_argument('--seed', type=int, default=0, help='seed of the fault schedule')
    parser.add_argument(
        '--stop-s', type=float, default=2.0, help="a stop's length: SIGSTOP to SIGCONT, s"
    )
    parser.add_argument(
        '--excitation', default='ambient', help="sim_node's excitation (ambient: never at rest)"
    )
    parser.add_argument('--no-replayer', dest='replayer', action='store_false')
    parser.add_argument('--no-shaper', dest='shaper', action='store_false')
    parser.add_argument(
        '--faults',
        type=lambda text: [k for k in text.split(',') if k in FAULTS] or list(FAULTS),
        default=list(FAULTS),
        help=f'the kinds of fault, comma-separated (default: all of {",".join(FAULTS)})',
    )
    parser.add_argument(
        '-p',
        dest='estimator_args',
        action='extend',
        default=['-p', 'excitation:=ambient'],
        type=lambda text: ['-p', text],
        metavar='NAME:=VALUE',
        help='an estimator_node parameter (repeatable; excitation:=ambient is set first, as for a '
        'structure the simulator drives with noise)',
    )
    parser.add_argument(
        '--sim-param',
        dest='sim_args',
        action='extend',
        default=[],
        type=lambda text: ['-p', text],
        metavar='NAME:=VALUE',
        help='a sim_node parameter (repeatable), e.g. "schedule:=[0.0, 0.0, 1.0, 0.0]": no '
        'ramp at each (re)start, the arm driven by the ambient disturbance (and the shaper) only',
    )
    parser.add_argument('--json', help='write the figures here')
    parser.add_argument(
        '--logs', help="keep the nodes' logs (stderr) in this directory (default: a temporary one)"
    )
    args = parser.parse_args(argv)
    if args.sim_hours:
        args.minutes = args.sim_hours * 60.0 / args.speed
    if args.fault_every is None:
        args.fault_every = 60.0 / args.speed if args.sim_hours else 24.0
    with tempfile.TemporaryDirectory(prefix='vib_soak_') as logs:
        if args.logs:
            logs = args.logs
            Path(logs).mkdir(parents=True, exist_ok=True)
        soak = Soak(args, Path(logs))
        try:
            fig = soak.run()
        except BaseException:
            for proc in soak.procs:
                proc.p.kill()
            raise
    report(fig)
    if args.json:
        Path(args.json).write_text(json.dumps(fig, indent=1, default=str))
    return 1 if fig['problems'] else 0


if __name__ == '__main__':
    sys.exit(main())
