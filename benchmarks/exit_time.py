# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""estimator_node's exit after SIGINT once it has run a while, optionally beside a CPU load.

    .venv/bin/python benchmarks/exit_time.py                      # 3 runs of 60 s, no load
    .venv/bin/python benchmarks/exit_time.py --load 2 --load-nice 0 --runs 2

Each run: ``sim_node`` at speed 10 (``excitation`` ambient) and ``estimator_node`` on it (its
defaults, ``use_sim_time``: after a minute the default has decided the identifier) for
``--seconds``; the simulator stopped (SIGINT), 3 s later SIGINT to the estimator (as the soak
does at its end): its exit code and the seconds from the signal to the process's end. The nodes
run at nice 10 (as the soak is run); ``--load N`` runs N ``yes`` at ``--load-nice`` meanwhile.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import time
from pathlib import Path


def executable(name: str) -> str:
    here = Path(sys.executable).parent / name
    return str(here) if here.exists() else name


def one_run(seconds: float, domain: int) -> tuple:
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    nice = ['nice', '-n', '10']
    quiet = dict(env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    sim_args = ['--ros-args', '-p', 'speed:=10.0', '-p', 'excitation:=ambient']
    sim = subprocess.Popen([*nice, executable('sim_node'), *sim_args], **quiet)
    est_args = ['--ros-args', '-p', 'use_sim_time:=true']
    est = subprocess.Popen([*nice, executable('estimator_node'), *est_args], **quiet)
    try:
        time.sleep(seconds)
        sim.send_signal(signal.SIGINT)
        sim.wait(30)
        time.sleep(3.0)
        t0 = time.monotonic()
        est.send_signal(signal.SIGINT)
        code = est.wait(30)
        return code, time.monotonic() - t0, os.getloadavg()[0]
    finally:
        for proc in (sim, est):
            if proc.poll() is None:
                proc.kill()
                proc.wait()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=3)
    parser.add_argument('--seconds', type=float, default=60.0, help='each run, before SIGINT')
    parser.add_argument('--load', type=int, default=0, help='this many `yes` meanwhile')
    parser.add_argument('--load-nice', type=int, default=10, help="the `yes`' nice level")
    args = parser.parse_args(argv)
    load = [
        subprocess.Popen(['nice', '-n', str(args.load_nice), 'yes'], stdout=subprocess.DEVNULL)
        for _ in range(args.load)
    ]
    try:
        for k in range(args.runs):
            code, seconds, avg = one_run(args.seconds, 150 + (os.getpid() + k) % 50)
            print(f'run {k + 1}: exit {code} after {seconds:.3f} s (load average {avg:.1f})')
    finally:
        for proc in load:
            proc.kill()
            proc.wait()
    return 0


if __name__ == '__main__':
    sys.exit(main())
