# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Nodes refusing to start, many at once: does every process end (exit 2, one ``error:`` line)?

    .venv/bin/python benchmarks/refusals.py                 # 15 rounds of 12 bag_replayers
    .venv/bin/python benchmarks/refusals.py --rounds 5 --timeout 30

Each round starts twelve ``bag_replayer`` processes at once (``python -m``, as the suite starts
them), each refusing a different start (a missing bag, no bag, a rate of the wrong type or out of
range, an unknown topic, a bad remap, an offset past the bag's end, ... on ``bags/arm_5_3``), and
waits ``--timeout`` s for each. Each process's participant is created, then the node refuses: a
crowd of participants appearing and leaving together, where destroying the refusing node's
participant deadlocked Fast DDS 2.14 in about one round of two (docs/nodes.md, "Stopping").
Prints per round the exit codes so far and the slowest process; a process that does not end is
killed and listed. Exit 1 when any process did not end with 2 and one ``error:`` line.
"""

from __future__ import annotations

import argparse
import collections
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BAG = ROOT / 'bags' / 'arm_5_3'
#: name -> the parameters each refusing process gets
REFUSALS = {
    'missing bag': ['bag:=/nonexistent/bag'],
    'no bag': [],
    'integer rate': [f'bag:={BAG}', 'rate:=10'],
    'zero rate': [f'bag:={BAG}', 'rate:=0.0'],
    'unknown topic': [f'bag:={BAG}', 'topics:=[/nope]'],
    'bad remap': [f'bag:={BAG}', 'remap:=[/coupling_torque]'],
    'offset past end': [f'bag:={BAG}', 'start_offset:=1000000.0'],
    'negative delay': [f'bag:={BAG}', 'delay:=-1.0'],
    'string loop': [f'bag:={BAG}', 'loop:=maybe'],
    'missing bag 2': ['bag:=/nonexistent/other.mcap'],
    'integer offset': [f'bag:={BAG}', 'start_offset:=3'],
    'bad clock': [f'bag:={BAG}', 'clock_hz:=-5.0'],
}


def one_round(env: dict, timeout: float):
    """Start every refusal at once; (name, exit code, seconds, stderr) each."""
    procs = {
        name: (
            subprocess.Popen(
                [sys.executable, '-m', 'vib_estimator.nodes.bag_replayer', '--ros-args']
                + [a for p in params for a in ('-p', p)],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
                text=True,
                env=env,
            ),
            time.monotonic(),
        )
        for name, params in REFUSALS.items()
    }
    results = []
    for name, (proc, start) in procs.items():
        try:
            _, err = proc.communicate(timeout=max(0.1, timeout - (time.monotonic() - start)))
        except subprocess.TimeoutExpired:
            proc.kill()
            _, err = proc.communicate()
            err += f'\n[killed after {timeout:g} s]'
        results.append((name, proc.returncode, time.monotonic() - start, err))
    return results


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--rounds', type=int, default=15)
    parser.add_argument('--timeout', type=float, default=60.0, help='seconds per process')
    parser.add_argument('--domain', type=int, default=os.getpid() % 100 + 100)
    args = parser.parse_args()
    env = {
        **os.environ,
        'ROS_DOMAIN_ID': str(args.domain),
        'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
    }
    codes = collections.Counter()
    bad = 0
    for r in range(args.rounds):
        results = one_round(env, args.timeout)
        for name, code, seconds, err in results:
            codes[code] += 1
            lines = [line for line in err.splitlines() if line.startswith('error: ')]
            if code != 2 or len(lines) != 1:
                bad += 1
                print(f'  {name}: exit {code} after {seconds:.1f} s\n{err[-2000:]}')
        slowest = max(results, key=lambda x: x[2])
        print(
            f'round {r + 1}: exit codes so far {dict(codes)}; slowest {slowest[0]} '
            f'{slowest[2]:.1f} s',
            flush=True,
        )
    print(f'{bad} of {sum(codes.values())} refusals did not end with exit 2 and one error line')
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
