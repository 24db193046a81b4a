# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Start-to-ready of the nodes and of ``analyze``, cold and warm, beside a reference commit.

    .venv/bin/python benchmarks/bench_startup.py                 # this tree vs 7374e6d
    .venv/bin/python benchmarks/bench_startup.py --ref HEAD~1 --only estimator_node

Prints figures, asserts nothing (a few minutes: every cold case compiles from nothing).

Each case runs as a new process, first **cold** (``NUMBA_CACHE_DIR`` an empty folder: a fresh
install that skipped ``make setup``'s warm-up) then **warm** (the same folder, filled by the cold
run). The reference is the same case run from ``git archive REF`` (``PYTHONPATH`` first), in the
same run, on the same machine state.

* ``estimator_node`` (default configuration, ``modes: 3``, ``band_hz: [1, 20]``): this process
  publishes a 5 Hz sine on ``coupling_torque`` (WrenchStamped, 500 samples/s of stamps, paced in
  real time) from one second after the node subscribes (discovery settled both ways). *live*:
  spawn to the node's first ``/diagnostics``, and the longest silence of ``/diagnostics`` after it
  (a node blocked in a compile says nothing); *ready*: spawn to the first ``~/self_test`` answer
  that is not "busy" (called every 0.1 s: the tones ran, compiled or uncompiled); *first
  estimate*: from the first sample sent to the first ``vibration/frequency`` (and from spawn);
  *lost*: samples sent that the node never counted (its ``received`` + ``dropped_warmup`` against
  what was sent). Then SIGINT: the exit code.
* ``shaper_node``: spawn to its first ``/diagnostics``.
* ``analyze``: the whole ``vib-estimator analyze`` of a 20 s CSV (a 5 Hz sine at 500 Hz: the
  free-decay estimator) and of an 11 s two-mode free decay (10 and 13 Hz, 1 : 0.5, at 1 kHz, as
  ``bench_defaults.py`` makes it: the default chooses the mode tracker), wall and CPU seconds.
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import signal
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ.setdefault('ROS_DOMAIN_ID', str(1 + os.getpid() % 101))
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

ROOT = Path(__file__).resolve().parents[1]
RATE_HZ = 500.0
TONE_HZ = 5.0
TIMEOUT_S = 180.0
ESTIMATOR_CASES = {
    'estimator_node (default)': [],
    'estimator_node (modes: 3)': ['modes:=3'],
    'estimator_node (band_hz)': ['band_hz:=[1.0, 20.0]'],
}
GOALS = 'goals: warm ready <= 2 s, cold ready <= 10 s, cold first estimate <= 10 s after spawn'


def node_command(tree: Path, module: str, params):
    code = f'import sys; from {module} import main; sys.exit(main())'
    # -P: without it ``-c`` puts the working directory ahead of PYTHONPATH, and a run from the
    # repository measured this tree's package for the reference too (figures before 2026-12-05)
    cmd = [sys.executable, '-P', '-c', code, '--ros-args']
    for p in params:
        cmd += ['-p', p]
    return cmd


def environment(tree: Path, cache: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    env['PYTHONPATH'] = os.pathsep.join([str(tree)] + [p for p in [env.get('PYTHONPATH')] if p])
    return env


class Probe:
    """This process's ROS side: the sine publisher, and subscribers to what the node says."""

    def __init__(self):
        import rclpy
        from diagnostic_msgs.msg import DiagnosticArray
        from geometry_msgs.msg import WrenchStamped
        from rclpy.qos import qos_profile_sensor_data
        from std_msgs.msg import Float64

        from vib_estimator.nodes.runner import make_executor

        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=int(os.environ['ROS_DOMAIN_ID']))
        self.node = rclpy.create_node('bench_startup', context=self.context)
        self.executor = make_executor(self.context)
        self.executor.add_node(self.node)
        self.msg_type = WrenchStamped
        self.pub = self.node.create_publisher(
            WrenchStamped, 'coupling_torque', qos_profile_sensor_data
        )
        self.node.create_subscription(Float64, 'vibration/frequency', self._on_frequency, 10)
        self.node.create_subscription(DiagnosticArray, '/diagnostics', self._on_diagnostics, 10)
        from std_srvs.srv import Trigger

        self.self_test = self.node.create_client(Trigger, '/estimator_node/self_test')
        self.trigger = Trigger.Request
        self.reset()

    def reset(self, pid=None):
        self.pid = pid
        self.first_estimate = None
        self.first_estimate_cpu = math.nan
        self.first_diag = {}
        self.diag_times = []
        self.last_values = {}

    def _on_frequency(self, msg):
        if self.first_estimate is None:
            self.first_estimate = time.monotonic()
            self.first_estimate_cpu = cpu_seconds(self.pid) if self.pid else math.nan

    def _on_diagnostics(self, msg):
        self.diag_times.append(time.monotonic())
        for status in msg.status:
            self.first_diag.setdefault(status.name, time.monotonic())
            self.last_values[status.name] = {kv.key: kv.value for kv in status.values}

    def spin(self, seconds):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=min(0.005, max(0.0, end - time.monotonic())))

    def _ask_self_test(self, state):
        """Keep calling ~/self_test until it answers (not busy compiling, whatever the tones
        gave); state['ready'] = the time it did."""
        future = state.get('future')
        if future is not None and future.done():
            result = future.result()
            if result is not None and not result.message.startswith('busy'):
                state['ready'] = time.monotonic()
                state['cpu'] = cpu_seconds(state['pid'])
            state['future'] = None
            state['next'] = time.monotonic() + 0.1
        elif (
            future is None
            and time.monotonic() >= state.get('next', 0.0)
            and self.self_test.service_is_ready()
        ):
            state['future'] = self.self_test.call_async(self.trigger())

    def estimator(self, cmd, env):
        """(live s, ready s, first estimate s after the first sample, lost samples, exit code)
        of one estimator_node start."""
        self.reset()
        start = time.monotonic()
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.pid = proc.pid
        sent = 0
        msg = self.msg_type()
        state = {'pid': proc.pid}
        matched = None
        try:
            while (
                self.first_estimate is None or 'ready' not in state
            ) and time.monotonic() - start < TIMEOUT_S:
                if proc.poll() is not None:
                    break
                if 'ready' not in state:
                    self._ask_self_test(state)
                if matched is None and self.pub.get_subscription_count():
                    matched = time.monotonic()
                # one second after the match, discovery has settled both ways: send, real time
                if matched is not None and time.monotonic() > matched + 1.0:
                    first = matched + 1.0
                    due = int((time.monotonic() - first) * RATE_HZ)
                    while sent < due:
                        ns = 1_000_000_000 + int(sent * 1e9 / RATE_HZ)
                        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(ns, 10**9)
                        msg.wrench.torque.z = math.sin(2 * math.pi * TONE_HZ * sent / RATE_HZ)
                        self.pub.publish(msg)
                        sent += 1
                self.spin(0.002)
            ready = state['ready'] - start if 'ready' in state else math.nan
            latency = self.first_estimate - first if self.first_estimate else math.nan
            spawned = self.first_estimate - start if self.first_estimate else math.nan
            cpu = state.get('cpu', math.nan)
            self.spin(1.5)  # a diagnostics period after the first estimate
            live = min(self.first_diag.values(), default=math.nan) - start
            # the longest /diagnostics silence, from the first one to 1.5 s after ready
            gaps = np.diff(self.diag_times)
            silence = float(gaps.max()) if len(gaps) else math.nan
            # the background compile's end (no warmup_s any more): the warm run finds it all
            while time.monotonic() - start < TIMEOUT_S and proc.poll() is None:
                now = next(iter(self.last_values.values()), {})
                if now and 'warmup_s' not in now:
                    break
                self.spin(0.05)
            compiled, compiled_cpu = time.monotonic() - start, cpu_seconds(proc.pid)
            # lost: never counted, once the node has drained what it had queued (a node behind
            # its input while it compiles holds up to its input depth, 10 s at 500 Hz)
            self.spin(2.5)
            values = next(iter(self.last_values.values()), {})
            counted = int(values.get('received', 0)) + int(values.get('dropped_warmup', 0))
            lost = sent - counted if values else -1
        finally:
            code = stop(proc)
        self.pid = None
        return (
            live,
            ready,
            latency,
            lost,
            code,
            silence,
            spawned,
            cpu,
            compiled,
            compiled_cpu,
            self.first_estimate_cpu,
        )

    def first_diagnostics(self, cmd, env):
        """(spawn to first /diagnostics s, exit code) of a node."""
        self.reset()
        start = time.monotonic()
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            while (
                not self.first_diag
                and time.monotonic() - start < TIMEOUT_S
                and proc.poll() is None
            ):
                self.spin(0.005)
            live = min(self.first_diag.values(), default=math.nan) - start
        finally:
            code = stop(proc)
        return live, code

    def close(self):
        self.executor.shutdown()
        self.node.destroy_node()
        self.context.try_shutdown()


def cpu_seconds(pid: int) -> float:
    """CPU seconds (user + system) process ``pid`` used so far: what a start costs whatever the
    machine's load (its wall-clock figures grow with it)."""
    try:
        with open(f'/proc/{pid}/stat') as stat:
            fields = stat.read().rsplit(')', 1)[1].split()
    except OSError:
        return math.nan
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def stop(proc) -> int:
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            return proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
            return -9
    return proc.returncode


def analyze_seconds(tree: Path, env: dict, csv: Path, extra=()):
    """(wall s, CPU s) of one ``vib-estimator analyze csv *extra`` (nan, nan if it failed)."""
    code = 'import sys; from vib_estimator.cli import main; sys.exit(main())'
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    done = subprocess.run(
        [sys.executable, '-P', '-c', code, 'analyze', str(csv), *extra],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    wall = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    return (math.nan, math.nan) if done.returncode else (wall, cpu)


def write_csv(path: Path, t, y) -> Path:
    np.savetxt(path, np.column_stack([t, y]), delimiter=',', header='t,y', comments='', fmt='%.9g')
    return path


def two_mode_decay() -> tuple:
    """bench_defaults.py's 'decay 10 / 13 Hz, 1:0.5': 1 s of noise, then the decay, 1 kHz."""
    rng = np.random.default_rng(0)
    rng.standard_normal(5000)  # bench_defaults draws the 5 Hz decay's noise first
    t = np.arange(0, 11, 0.001)
    tau = np.maximum(t - 1.0, 0)
    y = sum(
        a * np.exp(-z * 2 * np.pi * f * tau) * np.sin(2 * np.pi * f * tau)
        for f, a, z in ((10.0, 1.0, 0.003), (13.0, 0.5, 0.003))
    )
    return t, y + 0.05 / np.sqrt(2) * 10 ** (-1.5) * rng.standard_normal(len(t))


def checkout(ref: str, where: Path) -> Path:
    """``git archive ref`` unpacked into ``where``."""
    archive = where / 'ref.tar'
    subprocess.run(['git', '-C', str(ROOT), 'archive', '-o', str(archive), ref], check=True)
    with tarfile.open(archive) as tar:
        tar.extractall(where / 'tree', filter='data')
    return where / 'tree'


def noted(rows: list, row: tuple, text: str) -> None:
    """Keep a result row (case, tree, cold/warm, live, ready, lost, exit, first estimate, longest
    silence, first estimate after spawn, CPU s to ready, compiled after spawn s, its CPU s) and
    print it as it comes."""
    rows.append(row)
    case, label, kind = row[:3]
    print(f'{case:28s} {label:8s} {kind}: {text}', flush=True)


def runs(trees: dict, repeat: int):
    """(label, tree) of each run: every tree ``repeat`` times, labelled ``today#2`` etc."""
    for k in range(repeat):
        for label, tree in trees.items():
            yield (label if k == 0 else f'{label}#{k + 1}'), tree


def print_runs(rows: list) -> None:
    """One table line per case and run (--no-ref, --repeat): ready, first estimate (after the
    first sample; after spawn) and CPU s to ready, cold and warm."""
    print(
        '\n| case | run | ready, cold / warm | first estimate after the first sample, cold / warm '
        '| first estimate after spawn, cold / warm (CPU s) | CPU s to ready, cold / warm '
        '| lost, cold / warm | exit |'
    )
    print('|---|---|---|---|---|---|---|---|')
    for case, label in dict.fromkeys((r[0], r[1]) for r in rows):
        get = {r[2]: r for r in rows if r[:2] == (case, label)}
        c, w = get['cold'], get['warm']
        print(
            f'| {case} | {label} | {c[4]:.2f} / {w[4]:.2f} s | {c[7]:.2f} / {w[7]:.2f} s | '
            f'{c[9]:.2f} / {w[9]:.2f} s ({c[13]:.2f} / {w[13]:.2f}) | {c[10]:.2f} / {w[10]:.2f} '
            f'| {c[5]} / {w[5]} | {c[6]}, {w[6]} |'
        )


def main(argv=None) -> int:
    global TIMEOUT_S
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--ref', default='7374e6d', help='reference commit (default 7374e6d)')
    parser.add_argument(
        '--only',
        choices=['estimator_node', 'shaper_node', 'analyze'],
        action='append',
        help='run only these cases (repeatable)',
    )
    parser.add_argument(
        '--timeout',
        type=float,
        default=TIMEOUT_S,
        help='seconds a node start may take, its background compile included',
    )
    parser.add_argument(
        '--no-ref', action='store_true', help='this tree only (no reference commit)'
    )
    parser.add_argument(
        '--repeat', type=int, default=1, help='run each case (cold, then warm) this many times'
    )
    parser.add_argument(
        '--case',
        action='append',
        help='only the estimator_node cases whose name holds this (repeatable), e.g. modes',
    )
    args = parser.parse_args(argv)
    TIMEOUT_S = args.timeout
    only = set(args.only or ['estimator_node', 'shaper_node', 'analyze'])
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        trees = (
            {'today': ROOT} if args.no_ref else {'today': ROOT, args.ref: checkout(args.ref, tmp)}
        )
        t = np.arange(int(20 * RATE_HZ)) / RATE_HZ
        records = {
            'analyze (20 s CSV)': write_csv(tmp / 'tone.csv', t, np.sin(2 * np.pi * TONE_HZ * t)),
            'analyze (two-mode decay)': write_csv(tmp / 'two.csv', *two_mode_decay()),
        }
        probe = Probe()
        rows = []
        try:
            for case, params in ESTIMATOR_CASES.items():
                if 'estimator_node' not in only:
                    break
                if args.case and not any(c in case for c in args.case):
                    continue
                for label, tree in runs(trees, args.repeat):
                    cache = tempfile.mkdtemp(dir=tmp)
                    cmd = node_command(tree, 'vib_estimator.nodes.estimator_node', params)
                    for kind in ('cold', 'warm'):
                        got = probe.estimator(cmd, environment(tree, cache))
                        live, ready, latency, lost, code, silence, spawned, cpu, compiled, ccpu = (
                            got[:10]
                        )
                        noted(
                            rows,
                            (
                                case,
                                label,
                                kind,
                                live,
                                ready,
                                lost,
                                code,
                                latency,
                                silence,
                                spawned,
                                cpu,
                                compiled,
                                ccpu,
                                got[10],
                            ),
                            f'live {live:6.2f} s (longest /diagnostics silence {silence:5.2f} '
                            f's), ready {ready:6.2f} s, first estimate {latency:6.2f} s after '
                            f'the first sample ({spawned:6.2f} s after spawn, {got[10]:5.2f} CPU '
                            f's), lost {lost}, '
                            f'exit {code}; {cpu:5.2f} CPU s to ready; compiled after '
                            f'{compiled:6.2f} s, {ccpu:5.2f} CPU s',
                        )
            if 'shaper_node' in only:
                for label, tree in runs(trees, args.repeat):
                    cache = tempfile.mkdtemp(dir=tmp)
                    cmd = node_command(tree, 'vib_estimator.nodes.shaper_node', [])
                    for kind in ('cold', 'warm'):
                        live, code = probe.first_diagnostics(cmd, environment(tree, cache))
                        row = ('shaper_node', label, kind, live, live, 0, code)
                        noted(rows, row + (math.nan,) * 7, f'live {live:6.2f} s, exit {code}')
            for case, csv in records.items() if 'analyze' in only else ():
                for label, tree in runs(trees, args.repeat):
                    cache = tempfile.mkdtemp(dir=tmp)
                    for kind in ('cold', 'warm'):
                        seconds, cpu = analyze_seconds(tree, environment(tree, cache), csv)
                        row = (case, label, kind, math.nan, seconds, 0, 0)
                        row += (math.nan,) * 3 + (cpu, math.nan, math.nan, math.nan)
                        noted(rows, row, f'{seconds:6.2f} s, {cpu:6.2f} CPU s')
        finally:
            probe.close()
    print(f'load average at the end: {os.getloadavg()}')
    if args.no_ref or args.repeat > 1:
        print_runs(rows)
        print(GOALS)
        return 0
    print(
        f'\n| case | cold ready, today | cold, {args.ref} | warm ready, today | warm, '
        f'{args.ref} | live: first /diagnostics; longest silence, cold today / {args.ref} | '
        f'first estimate after '
        f'the first sample, cold today / {args.ref} | first estimate after spawn, cold today / '
        f'{args.ref}; warm today / {args.ref} | CPU s to ready, cold today / {args.ref}; warm '
        f'today / {args.ref} | compiled (background), cold: s after spawn; CPU s, today / '
        f'{args.ref} | samples lost, cold today / {args.ref} | exit on SIGINT |'
    )
    print('|---|---|---|---|---|---|---|---|---|---|---|---|')
    cases = list(dict.fromkeys(r[0] for r in rows))
    for case in cases:
        get = {(r[1], r[2]): r for r in rows if r[0] == case}
        today_c, ref_c = get.get(('today', 'cold')), get.get((args.ref, 'cold'))
        today_w, ref_w = get.get(('today', 'warm')), get.get((args.ref, 'warm'))
        codes = sorted({r[6] for r in get.values()})
        print(
            f'| {case} | {today_c[4]:.1f} s | {ref_c[4]:.1f} s | {today_w[4]:.2f} s | '
            f'{ref_w[4]:.2f} s | {today_c[3]:.1f}; {today_c[8]:.1f} / {ref_c[3]:.1f}; '
            f'{ref_c[8]:.1f} s | '
            f'{today_c[7]:.1f} / {ref_c[7]:.1f} s | {today_c[9]:.1f} / {ref_c[9]:.1f}; '
            f'{today_w[9]:.1f} / {ref_w[9]:.1f} s | {today_c[10]:.1f} / {ref_c[10]:.1f}; '
            f'{today_w[10]:.2f} / {ref_w[10]:.2f} s | {today_c[11]:.1f}; {today_c[12]:.1f} / '
            f'{ref_c[11]:.1f}; {ref_c[12]:.1f} | {today_c[5]} / {ref_c[5]} | {codes} |'
        )
    print(GOALS)
    return 0


if __name__ == '__main__':
    sys.exit(main())
