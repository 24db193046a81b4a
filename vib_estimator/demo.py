"""``vib-estimator demo``: the simulated arm and the estimator node live, through three tip masses.

Starts ``sim_node`` (Section 5.5's masses 30 -> 45.55 -> 61.17 g, :func:`arm_model.schedule_5_5`,
sped up, publishing ``/clock``) and ``estimator_node`` (``use_sim_time``, the paper's configuration
:data:`PAPER_PARAMS`) as subprocesses of the
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
import math
import os
import signal
import subprocess
import sys
import time
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import List, Optional, Sequence, Tuple

import numpy as np

from .control.shaping import SHAPERS
from .core.config import PAPER
from .sim.arm_model import MASSES_5_5, natural_frequency_hz, schedule_5_5

#: estimator_node's parameters of the paper's configuration: the demo replays the paper's Section 5
#: (a simulated arm without offset), so its figures stay those of the paper's estimator
PAPER_PARAMS = tuple(f'{name}:={value}' for name, value in PAPER.items())
#: --real-arm: sim_node's realism of a real rig (docs/real_arm.md): a strain-gauge offset of half
#: the vibration's amplitude, a quantum of a tenth of it, a closed-loop limit cycle of ~0.3 N m;
#: estimator_node then runs with its defaults
REAL_ARM_SIM_PARAMS = ('offset:=-0.15', 'quantum:=0.03', 'limit_cycle_voltage:=0.3')
#: exit criterion: every mass's median |error| within this (%)
MAX_MEDIAN_ERROR_PCT = 3.0
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
#: --shaping: each shaped move must cut the vibration a move adds by this fraction (the issue's
#: goals: ZVD <= 10 % of the unshaped residual, ZV <= 20 %); shapers not listed: 0.9
MIN_REDUCTION = {'zv': 0.8}
DEFAULT_MIN_REDUCTION = 0.9
#: --shaping: the shortest --seconds-per-mass (two moves and their free vibration), the largest
#: --step, and the time after a move's last impulse before its vibration is measured (the PD loop
#: settles, the command's latency passes), s
MIN_SECONDS_PER_MOVE_PAIR = 6.0
MAX_STEP = 2.0
SETTLE_S = 0.3


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


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('--speed', type=float, default=10.0,
                        help='simulated seconds per wall-clock second (default 10)')
    parser.add_argument('--seconds-per-mass', type=float, default=8.0,
                        help='simulated seconds spent on each tip mass (default 8)')
    parser.add_argument('--out', default=None,
                        help='figure path (default out/demo.png, with --shaping out/shaping.png)')
    parser.add_argument('--domain-id', type=domain_id, default=None,
                        help='ROS domain of the demo, 0-232 (default: ROS_DOMAIN_ID when set, '
                             'else one of 1-101 from the process id)')
    parser.add_argument('--real-arm', action='store_true',
                        help='the same schedule on a realistic rig (strain-gauge offset, coarse '
                             'quantisation, a closed-loop limit cycle) with the estimator\'s '
                             'defaults instead of the paper\'s configuration (docs/real_arm.md)')
    parser.add_argument('--shaping', action='store_true',
                        help='input shaping: per mass a move unshaped, then the same move shaped '
                             'by shaper_node for the estimate (figure out/shaping.png)')
    parser.add_argument('--shaper', default='zvd', choices=sorted(SHAPERS),
                        help='with --shaping: the shaper of the shaped moves (default zvd)')
    parser.add_argument('--step', type=float, default=0.5,
                        help='with --shaping: size of each move (a reference step), rad '
                             '(default 0.5)')


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
        from diagnostic_msgs.msg import DiagnosticArray
        from geometry_msgs.msg import WrenchStamped
        from rclpy.node import Node
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from std_msgs.msg import Float64, Header

        from .nodes.sim_node import SIM_TIME_ORIGIN_NS
        from .nodes.stream import WARMUP_MESSAGE

        self._warmup_message = WARMUP_MESSAGE
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
        self.node.create_subscription(DiagnosticArray, '/diagnostics', self._on_diagnostics, 10)
        #: node names whose /diagnostics say they estimate (not warming up)
        self.ready: set = set()
        self._warming: set = set()

    def _on_diagnostics(self, msg) -> None:
        for status in msg.status:
            if status.message == self._warmup_message:
                if status.name not in self._warming:
                    self._warming.add(status.name)
                    print(f'{status.name}: {status.message}; the demo starts the simulator when '
                          'it is ready', flush=True)
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
    # a demo started from a background job inherits SIGINT ignored: give the nodes the default,
    # so that _stop's SIGINT ends them cleanly
    return subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


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

        from .nodes.runner import make_executor

        self.domain = demo_domain(args.domain_id, os.environ.get('ROS_DOMAIN_ID'))
        os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'   # read by rclpy.init below
        self.env = dict(os.environ, ROS_DOMAIN_ID=str(self.domain))
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=self.domain)
        self.executor = make_executor(self.context)
        self.listener = Listener(self.context, truth)
        self.executor.add_node(self.listener.node)
        self.procs: List[subprocess.Popen] = []

    def spin_until(self, predicate, timeout: float) -> bool:
        from .nodes.runner import spin_until
        return spin_until(self.executor, predicate, timeout)

    def start(self, exe: str, params: List[str], ready,
              timeout: float = STARTUP_TIMEOUT) -> subprocess.Popen:
        """Start a node; wait until ``ready()`` (or its exit); raise RuntimeError if it failed."""
        proc = _start(exe, params, self.env)
        self.procs.append(proc)
        up = self.spin_until(lambda: proc.poll() is not None or ready(), timeout)
        if not up or proc.poll() is not None:
            raise RuntimeError(f'{exe} did not come up' if proc.poll() is None
                               else f'{exe} exited with {proc.returncode}')
        return proc

    def start_estimator(self, params: Sequence[str] = ()) -> subprocess.Popen:
        """Start estimator_node (sim time, ``params`` on top) and wait until its kernels are compiled (its
        /diagnostics stop saying it warms up) and it sees the demo's topics."""
        listener = self.listener
        return self.start('estimator_node', ['use_sim_time:=true', *params], lambda: (
            '/estimator_node' in listener.ready and listener.counts('vibration/frequency')[0]
            and listener.counts('coupling_torque')[1]), WARMUP_TIMEOUT)

    def start_sim(self, params: List[str]) -> subprocess.Popen:
        sim = _start('sim_node', params, self.env)
        self.procs.append(sim)
        return sim

    def finish_sim(self, sim: subprocess.Popen, duration: float, speed: float) -> None:
        """Spin until sim_node exits; RuntimeError if it failed."""
        self.spin_until(lambda: sim.poll() is not None, STARTUP_TIMEOUT + duration / speed)
        self.spin_until(lambda: False, 0.5)   # the last messages in flight
        if sim.returncode != 0:
            raise RuntimeError('sim_node ' + ('did not finish in time' if sim.returncode is None
                                              else f'exited with {sim.returncode}'))

    def close(self) -> None:
        for proc in reversed(self.procs):
            _stop(proc)
        self.executor.shutdown()
        self.listener.node.destroy_node()
        self.context.try_shutdown()


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
    return [f'speed:={float(speed)}', f'duration:={float(duration)}', 'publish_clock:=true',
            f'wait_for_subscribers:={subscribers}',
            'schedule:=[' + ', '.join(map(repr, schedule)) + ']']


def run(args: argparse.Namespace) -> int:
    from rclpy.executors import ExternalShutdownException

    if args.speed <= 0 or args.seconds_per_mass <= 2:
        print('error: --speed must be > 0 and --seconds-per-mass > 2', file=sys.stderr)
        return 2
    if args.shaping and (args.seconds_per_mass < MIN_SECONDS_PER_MOVE_PAIR
                         or not 0 < args.step <= MAX_STEP):
        print(f'error: with --shaping, --seconds-per-mass must be >= '
              f'{MIN_SECONDS_PER_MOVE_PAIR:g} and --step in (0, {MAX_STEP:g}] rad',
              file=sys.stderr)
        return 2
    truth = [(i * args.seconds_per_mass, (i + 1) * args.seconds_per_mass, natural_frequency_hz(m))
             for i, m in enumerate(MASSES_5_5)]
    wall_start = time.monotonic()
    session = Session(args, truth)
    try:
        if args.shaping:
            return _run_shaping(session, args, wall_start)
        return _run_estimation(session, args, wall_start)
    except RuntimeError as err:
        print(f'error: {err}', file=sys.stderr)
        return 1
    except (KeyboardInterrupt, ExternalShutdownException):
        print('interrupted', file=sys.stderr)
        return 130
    finally:
        session.close()


def _run_estimation(session: Session, args: argparse.Namespace, wall_start: float) -> int:
    """The estimation demo: Section 5.5's schedule, every estimate against Eq. 23."""
    from .analysis.plotting import plot_estimates
    from .nodes.sim_node import schedule_to_array

    listener = session.listener
    duration = 3 * args.seconds_per_mass
    real = getattr(args, 'real_arm', False)
    print(f'demo: ROS domain {session.domain}, {duration:g} s simulated at {args.speed:g}x, tip '
          'masses ' + ' -> '.join(f'{m * 1e3:g} g' for m in MASSES_5_5)
          + (' on a realistic rig (' + ', '.join(REAL_ARM_SIM_PARAMS) + '), estimator defaults'
             if real else ''), flush=True)
    session.start_estimator([] if real else PAPER_PARAMS)
    sim = session.start_sim(sim_params(args.speed, duration,
                                       schedule_to_array(schedule_5_5(args.seconds_per_mass)), 2)
                            + list(REAL_ARM_SIM_PARAMS if real else ()))
    session.finish_sim(sim, duration, args.speed)
    rec = listener.record
    rows, ok = summarise(rec)
    print('\n' + '\n'.join(rows))
    out = Path(args.out or 'out/demo.png')
    out.parent.mkdir(parents=True, exist_ok=True)
    plot_estimates(str(out), np.asarray(rec.t), np.asarray(rec.torque), np.asarray(rec.est_t),
                   np.asarray(rec.est_f), np.asarray(rec.est_conv), rec.truth,
                   title=f'Simulated arm, tip masses 30 / 45.55 / 61.17 g ({args.speed:g}x)',
                   ylabel='coupling torque', unit='N·m')
    print(f'\n{len(rec.t)} samples, {len(rec.est_t)} estimates in '
          f'{time.monotonic() - wall_start:.1f} s; figure: {out}')
    print('PASS: every median error within 3 %' if ok
          else 'FAIL: a mass without estimates or with a median error above 3 %')
    return 0 if ok else 1


# ---- vib-estimator demo --shaping --------------------------------------------------------------
@dataclass
class ShapedMove:
    """One move of the shaping demo: its mass (index), its time (simulated), the new reference;
    for a shaped move the estimate it was shaped with and the shaper (while the demo runs:
    the shaper's name)."""

    mass: int
    t: float
    reference: float
    estimate: float = float('nan')
    shaper: object = None

    @property
    def duration(self) -> float:
        return self.shaper.duration if self.shaper is not None else 0.0


def shaping_events(seconds_per_mass: float, shaper: str, step: float
                   ) -> List[Tuple[float, str, object]]:
    """(simulated time, 'shaper' or 'move', value) for each mass: the shaper off, a move unshaped;
    half-way, the shaper on (it is designed for the estimates of the free vibration since), and
    the same move back."""
    events: List[Tuple[float, str, object]] = []
    for i in range(len(MASSES_5_5)):
        t0, half = i * seconds_per_mass, seconds_per_mass / 2
        events += [(t0 + 0.5, 'shaper', 'none'), (t0 + 1.0, 'move', step),
                   (t0 + half + 0.25, 'shaper', shaper), (t0 + half + 0.5, 'move', 0.0)]
    return events


class ShapingDriver:
    """Publishes the ``reference`` and switches ``shaper_node``'s ``shaper`` parameter."""

    def __init__(self, session: 'Session'):
        from rclpy.parameter_client import AsyncParameterClient
        from std_msgs.msg import Float64

        self._session = session
        self._msg = Float64
        node = session.listener.node
        self.reference_pub = node.create_publisher(Float64, 'reference', 10)
        self._params = AsyncParameterClient(node, 'shaper_node')

    def now(self) -> float:
        """The simulated time of the last sample heard, s."""
        t = self._session.listener.record.t
        return t[-1] if t else 0.0

    def set_shaper(self, name: str) -> None:
        from rclpy.parameter import Parameter

        future = self._params.set_parameters([Parameter('shaper', value=name)])
        if not self._session.spin_until(future.done, 10.0):
            raise RuntimeError('shaper_node did not answer a parameter request')
        result = future.result().results[0]
        if not result.successful:
            raise RuntimeError(f'shaper_node refused shaper {name}: {result.reason}')

    def move(self, reference: float) -> None:
        self.reference_pub.publish(self._msg(data=float(reference)))


def _last_estimate_before(rec: Record, t: float) -> float:
    before = [f for te, f in zip(rec.est_t, rec.est_f) if te <= t]
    return before[-1] if before else float('nan')


def _drive(session: 'Session', driver: ShapingDriver, sim, args) -> List[ShapedMove]:
    """Play the events as the simulated time reaches them; return the moves made (``t``: the
    time heard when commanded; the arm sees it later, see :func:`measure_moves`)."""
    moves: List[ShapedMove] = []
    name = 'none'
    for t, kind, value in shaping_events(args.seconds_per_mass, args.shaper, args.step):
        session.spin_until(lambda: sim.poll() is not None or driver.now() >= t,
                           STARTUP_TIMEOUT + 3 * args.seconds_per_mass / args.speed)
        if sim.poll() is not None:
            break
        if kind == 'shaper':
            driver.set_shaper(value)
            name = value
            continue
        moves.append(ShapedMove(int(t // args.seconds_per_mass), driver.now(), value,
                                shaper=name))
        driver.move(value)
        print(f'[{moves[-1].t:6.2f} s] move to {value:g} rad, {name}', flush=True)
    return moves


def _locate(rec: Record, move: ShapedMove, f0: float) -> None:
    """Set the move's onset in the signal, and for a shaped move the estimate it was shaped with
    (the last before the onset) and that design."""
    from .control.residual import move_onset
    from .control.shaping import design

    onset = move_onset(rec.t, rec.torque, move.t, f0, 0.004)
    if not math.isfinite(onset):
        raise RuntimeError(f'the move at {move.t:.2f} s does not show in the signal')
    move.t = onset
    name, move.shaper = move.shaper, None
    if name != 'none':
        move.estimate = _last_estimate_before(rec, onset)
        if not math.isfinite(move.estimate):
            raise RuntimeError(f'no estimate before the shaped move at {onset:.2f} s')
        move.shaper = design(name, move.estimate, 0.0)


def measure_moves(rec: Record, moves: List[ShapedMove], seconds_per_mass: float) -> List[dict]:
    """Per mass, the vibration its unshaped and its shaped move added (joint fit,
    :func:`vib_estimator.control.residual.added_vibration`, from each move's onset) and their
    ratio."""
    from .control.residual import added_vibration

    t, y = np.asarray(rec.t), np.asarray(rec.torque)
    rows = []
    for i, m in enumerate(MASSES_5_5):
        pair = [mv for mv in moves if mv.mass == i]
        if len(pair) != 2:
            continue
        f0 = natural_frequency_hz(m)
        for mv in pair:
            _locate(rec, mv, f0)
        unshaped, shaped = pair
        t_mass, t_next = i * seconds_per_mass, min((i + 1) * seconds_per_mass, t[-1])
        u_settled = unshaped.t + SETTLE_S
        s_settled = shaped.t + shaped.duration + SETTLE_S
        fit_u = added_vibration(t, y, unshaped.t, u_settled, unshaped.t - t_mass - 0.05,
                                shaped.t - u_settled, f0, 0.004)
        fit_s = added_vibration(t, y, shaped.t, s_settled, shaped.t - u_settled,
                                t_next - s_settled, f0, 0.004)
        rows.append({'mass_g': m * 1e3, 'f0': f0, 'estimate': shaped.estimate,
                     'unshaped': fit_u.added, 'shaped': fit_s.added,
                     'ratio': fit_s.added / fit_u.added, 'moves': (unshaped, shaped),
                     'fits': (fit_u, fit_s)})
    return rows


def summarise_shaping(rows: List[dict], shaper: str) -> Tuple[List[str], bool]:
    """The table of :func:`measure_moves` and whether every mass's shaped move cut the added
    vibration by at least the shaper's MIN_REDUCTION."""
    need = MIN_REDUCTION.get(shaper, DEFAULT_MIN_REDUCTION)
    lines = [f'{"mass g":>7} {"f0 Hz":>6} {"estimate Hz":>11} {"err %":>6} '
             f'{"unshaped N m":>12} {shaper + " N m":>10} {"ratio %":>7} {"reduction %":>11}']
    ok = len(rows) == len(MASSES_5_5)
    for r in rows:
        ok &= r['ratio'] <= 1 - need
        lines.append(f'{r["mass_g"]:7.2f} {r["f0"]:6.3f} {r["estimate"]:11.4f} '
                     f'{(r["estimate"] / r["f0"] - 1) * 100:+6.2f} {r["unshaped"]:12.4f} '
                     f'{r["shaped"]:10.4f} {r["ratio"] * 100:7.2f} {(1 - r["ratio"]) * 100:11.1f}')
    return lines, bool(ok)


def plot_shaping(path: str, rec: Record, rows: List[dict], shaper: str, speed: float) -> None:
    """Per mass what the unshaped and the shaped move did to the torque (the signal minus the
    vibration continued from before the move, from the fit), then the estimates against Eq. 23,
    each shaped move's impulses, and the vibration each move added."""
    from .analysis.plotting import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(13, 7))
    t, y = np.asarray(rec.t), np.asarray(rec.torque)
    for ax, r in zip(axes[0], rows):
        for mv, fit, label, color in zip(r['moves'], r['fits'], ('unshaped', shaper),
                                         ('C0', 'C3')):
            sel = (t >= mv.t - 0.5) & (t < mv.t + 3.0)
            ax.plot(t[sel] - mv.t, y[sel] - fit.continued(t[sel]), lw=0.7, color=color,
                    label=f'{label} (adds {fit.added:.3f})')
        ax.set_title(f'{r["mass_g"]:.2f} g, f0 {r["f0"]:.3f} Hz')
        ax.set_xlabel('time from the move (s)')
        ax.legend(loc='upper right', fontsize=8)
    axes[0][0].set_ylabel('torque minus the earlier vibration (N m)')
    axes[1][0].plot(rec.est_t, rec.est_f, '*', color='C3', label='estimates')
    for i, (t0, t1, f) in enumerate(rec.truth):
        axes[1][0].hlines(f, t0, t1, colors='k', linestyles='--',
                          label='Eq. 23' if i == 0 else None)
    axes[1][0].set(xlabel='time (s)', ylabel='frequency (Hz)', ylim=(0.9, 2.0))
    axes[1][0].legend(fontsize=8)
    for i, r in enumerate(rows):
        s = r['moves'][1].shaper
        if s is not None:
            axes[1][1].stem(s.times, s.amplitudes, linefmt=f'C{i}-', markerfmt=f'C{i}o',
                            basefmt=' ', label=f'{r["mass_g"]:.0f} g: {r["estimate"]:.3f} Hz')
    axes[1][1].set(xlabel='impulse time (s)', ylabel='amplitude', title=f'{shaper} impulses')
    axes[1][1].legend(fontsize=8)
    x = np.arange(len(rows))
    axes[1][2].bar(x - 0.2, [r['unshaped'] for r in rows], 0.4, label='unshaped')
    axes[1][2].bar(x + 0.2, [r['shaped'] for r in rows], 0.4, label=shaper, color='C3')
    axes[1][2].set(xticks=x, xticklabels=[f'{r["mass_g"]:.0f} g' for r in rows], yscale='log',
                   ylabel='vibration the move adds (N m)')
    axes[1][2].legend(fontsize=8)
    fig.suptitle(f'Input shaping with the on-line estimate, simulated arm ({speed:g}x)')
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _run_shaping(session: 'Session', args: argparse.Namespace, wall_start: float) -> int:
    """The shaping demo: per mass a move unshaped, then shaped by shaper_node for the estimate."""
    from .nodes.sim_node import schedule_to_array
    from .sim.arm_model import Move

    listener = session.listener
    p = args.seconds_per_mass
    print(f'demo --shaping: ROS domain {session.domain}, {3 * p:g} s simulated at '
          f'{args.speed:g}x, {args.shaper}, steps of {args.step:g} rad, tip masses '
          + ' -> '.join(f'{m * 1e3:g} g' for m in MASSES_5_5), flush=True)
    session.start_estimator(PAPER_PARAMS)
    driver = ShapingDriver(session)
    session.start('shaper_node', ['use_sim_time:=true', 'shaper:=none'], lambda: (
        driver.reference_pub.get_subscription_count()
        and listener.counts('position_command')[0]))
    driver.move(0.0)                                    # the shaper holds the arm at 0
    masses = [Move(i * p, 0.0, 1.0, m) for i, m in enumerate(MASSES_5_5)]
    lockstep = args.speed != 1        # in real time the arm takes the commands as they come
    sim_start = time.monotonic()
    sim = session.start_sim(sim_params(args.speed, 3 * p, schedule_to_array(masses), 2)
                            + ['wait_for_command:=true', f'lockstep:={str(lockstep).lower()}'])
    moves = _drive(session, driver, sim, args)
    session.finish_sim(sim, 3 * p, args.speed)
    sim_wall = time.monotonic() - sim_start
    rows = measure_moves(listener.record, moves, p)
    lines, ok = summarise_shaping(rows, args.shaper)
    print('\nvibration each move adds (joint fit of the free vibration before and after it):')
    print('\n'.join(lines))
    out = Path(args.out or 'out/shaping.png')
    out.parent.mkdir(parents=True, exist_ok=True)
    plot_shaping(str(out), listener.record, rows, args.shaper, args.speed)
    need = MIN_REDUCTION.get(args.shaper, DEFAULT_MIN_REDUCTION) * 100
    print(f'\n{len(listener.record.t)} samples; {3 * p:g} s simulated in {sim_wall:.1f} s '
          f'({3 * p / sim_wall:.1f}x achieved of {args.speed:g}x'
          f'{", lockstep" if lockstep else ""}), '
          f'{time.monotonic() - wall_start:.1f} s in all; figure: {out}')
    print(f'PASS: every shaped move cut the vibration it adds by >= {need:g} %' if ok else
          f'FAIL: a shaped move cut the vibration it adds by less than {need:g} %')
    return 0 if ok else 1
