# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Does a node with several ``components`` keep up? The node's data path without ROS.

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_channels_node.py [--channels 6]
        [--rate 1000] [--seconds 60]

Feeds a record (4 modes 3-40 Hz on ``--channels`` channels, 20 dB, window 30 s) sample by sample
through :class:`vib_estimator.nodes.stream.EstimatorStream` -- what ``estimator_node`` calls per
message, after converting it -- with ``components`` (the joint identifier), beside one channel of
the same record through the single-channel ambient identifier, same run: multiples of real time,
and the longest single call (an analysis: the samples that queue meanwhile must fit the input
history, 1000). The per-message cost of rclpy itself is ``bench_node.py``'s.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from vib_estimator.core import EstimatorConfig
from vib_estimator.nodes.stream import EstimatorStream
from vib_estimator.sim.frame import modal_record

MODES = [(3.0, 0.02, 1.0), (9.0, 0.01, 0.5), (21.0, 0.01, 0.3), (40.0, 0.005, 0.2)]


def run(stamps, samples, channels, seconds):
    """(multiple of real time, estimates, longest call s) of one stream fed ``samples``."""
    config = EstimatorConfig(excitation='ambient', ambient_window_s=30.0)
    feed = EstimatorStream(config, 0.0, channels=channels).feed
    estimates, longest = 0, 0.0
    start = time.perf_counter()
    for stamp, value in zip(stamps, samples):
        before = time.perf_counter()
        estimates += len(feed(stamp, value))
        longest = max(longest, time.perf_counter() - before)
    return seconds / (time.perf_counter() - start), estimates, longest


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--channels', type=int, default=6)
    parser.add_argument('--rate', type=float, default=1000.0)
    parser.add_argument('--seconds', type=float, default=60.0)
    args = parser.parse_args()
    shapes = np.random.default_rng(7).uniform(-1, 1, (args.channels, len(MODES)))
    t, y = modal_record(args.seconds, args.rate, MODES, shapes, 20.0, 8)
    stamps = (10**18 + np.round(t * 1e9).astype(np.int64)).tolist()
    names = [f'c{i}' for i in range(args.channels)]
    print(f'{args.channels} channels at {args.rate:g} Hz, {args.seconds:g} s, window 30 s')
    for label, channels, samples in (
        (f'components ({args.channels})', names, [tuple(row) for row in y.tolist()]),
        ('one channel', (), y[:, 0].tolist()),
    ):
        speed, estimates, longest = run(stamps, samples, channels, args.seconds)
        print(
            f'{label}: {speed:.1f}x real time, {estimates} estimates, longest call '
            f'{1e3 * longest:.0f} ms'
        )


if __name__ == '__main__':
    main()
