# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""What grows in the estimator node's data path: RSS and the Python heap over simulated time.

    .venv/bin/python benchmarks/stream_memory.py                       # 30 min, excitation ambient
    .venv/bin/python benchmarks/stream_memory.py --excitation free     # the default (it decides)
    .venv/bin/python benchmarks/stream_memory.py --minutes 10 --trace  # and where the heap grew

:class:`~vib_estimator.nodes.stream.EstimatorStream` (the node's processing without ROS: its
estimator, decision and counters) fed ``sim_node``'s arm (``excitation`` ambient, its start ramp,
500 Hz) in one process, as fast as it goes, with the soak's faults every 240 simulated s in turn:
the simulator restarted (its stamps back to 1 s), a stall (10 s of samples lost: a gap), a
parameter storm (100 estimators built), 50 resets and self-tests, a publisher gone (restarted),
and the decisions applied once a second of the soak's wall time (5000 samples), as the node does.
Prints RSS every 5 simulated minutes (after a garbage collection); ``--trace``: tracemalloc's
growth from the 5th minute to the end, by line, and the object counts that grew. glibc's mmap
threshold is fixed first, as ``estimator_node`` fixes it (``fix_allocator``);
``--keep-allocator`` leaves glibc's dynamic threshold (the node before 5 Dec 2026).
"""

from __future__ import annotations

import argparse
import collections
import dataclasses
import gc
import tracemalloc

from vib_estimator.core.config import EstimatorConfig
from vib_estimator.nodes.sim_node import PARAMETERS, make_simulator, schedule_from_array
from vib_estimator.nodes.stream import EstimatorStream, fix_allocator

RATE_HZ = 500.0
#: samples between two of the node's status/decision calls (a wall second at speed 10)
TICK = 5000
#: a fault every this many samples (240 simulated s: the 6-minute soak's 24 s at speed 10)
FAULT_EVERY = int(240 * RATE_HZ)
FAULTS = ('restart', 'stop', 'storm', 'calls', 'gone')


def rss_mb() -> float:
    with open('/proc/self/status') as status:
        kb = next(int(line.split()[1]) for line in status if line.startswith('VmRSS'))
    return kb / 1024


def simulator(seed: int):
    p = {name: default for name, (default, _) in PARAMETERS.items()}
    p.update(excitation='ambient', seed=seed)
    return make_simulator(p, schedule_from_array(p['schedule']), 'geometry_msgs/msg/WrenchStamped')


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--minutes', type=float, default=30.0, help='simulated minutes')
    parser.add_argument('--excitation', default='ambient', help="the estimator's excitation")
    parser.add_argument('--trace', action='store_true', help='tracemalloc from the 5th minute')
    parser.add_argument(
        '--keep-allocator', action='store_true', help="glibc's dynamic mmap threshold (not fixed)"
    )
    args = parser.parse_args(argv)
    if not args.keep_allocator:
        fix_allocator()  # as estimator_node does
    stream = EstimatorStream(EstimatorConfig(excitation=args.excitation), 0.0, deciding=True)
    sim, runs, k, n, faults = simulator(0), 0, 0, 0, 0
    total = int(args.minutes * 60 * RATE_HZ)
    every = int(300 * RATE_HZ)
    if args.trace:
        tracemalloc.start()
    first = None
    while n < total:
        for _ in range(TICK):
            _, y, _ = sim.step()
            stream.feed(10**9 + round(k * 1e9 / RATE_HZ), y)
            k, n = k + 1, n + 1
        stream.status(n / RATE_HZ / 10)
        decision = stream.decision()
        if decision is not None:
            stream.configure(dataclasses.replace(stream.config, **decision.changes()), prime=True)
            stream.decided = True
        if n % FAULT_EVERY < TICK:
            kind = FAULTS[faults % len(FAULTS)]
            faults += 1
            if kind in ('restart', 'gone'):
                runs += 1
                sim, k = simulator(runs), 0
            elif kind == 'stop':
                for _ in range(int(10 * RATE_HZ)):
                    sim.step()
                k += int(10 * RATE_HZ)
            elif kind == 'storm':
                for _ in range(100):
                    stream.configure(dataclasses.replace(stream.config, max_gap=0.5))
            else:
                for _ in range(50):
                    stream.reset()
                    stream.self_test()
        if n % every < TICK:
            gc.collect()
            config = stream.config
            print(
                f'{n / RATE_HZ / 60:6.1f} simulated min  RSS {rss_mb():6.1f} MB  '
                f'estimates {stream.counters["estimates"]}  excitation {config.excitation} '
                f'(window {config.ambient_window_s:.0f} s)',
                flush=True,
            )
            if args.trace and first is None:
                first = (
                    tracemalloc.take_snapshot(),
                    collections.Counter(type(o).__name__ for o in gc.get_objects()),
                )
    if args.trace and first is not None:
        grown = collections.Counter(type(o).__name__ for o in gc.get_objects()) - first[1]
        print(f'Python heap traced: {tracemalloc.get_traced_memory()[0] / 2**20:.1f} MB')
        print('objects grown:', ', '.join(f'{name} {n}' for name, n in grown.most_common(6)))
        for stat in tracemalloc.take_snapshot().compare_to(first[0], 'lineno')[:8]:
            print(stat)


if __name__ == '__main__':
    main()
