# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Reading a bag with its records checked (io/mcap.py) beside rosbags' own reader, same run.

A 200 000-message WrenchStamped bag (64 KiB chunks with CRC-32, as BagWriter writes them) is read
by: the streaming fast path (``open_signal``: chunks checked, payloads decoded at once), the bag
reader behind the replayer (``BagReader.messages``: chunks checked and each payload CDR-decoded;
and with ``check=False``), and, as the reference, rosbags' MCAP reader iterating the raw messages
(it checks the chunk CRCs too, but stops at the first damaged one). Best of 3 wall-clock runs.

    python benchmarks/bench_bags.py [--messages N]
"""

from __future__ import annotations

import argparse
import tempfile
import timeit
from pathlib import Path

import numpy as np
from rosbags.rosbag2 import Reader

from vib_estimator.io.bags import BagReader, WrenchSeries, write_wrench_series
from vib_estimator.io.streaming import open_signal


def best(run, repeat: int = 3) -> float:
    """The shortest of ``repeat`` runs, s."""
    return min(timeit.repeat(run, number=1, repeat=repeat))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--messages', type=int, default=200_000)
    n = parser.parse_args().messages
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / 'bag'
        stamps = 1_700_000_000 * 10**9 + np.arange(n, dtype=np.int64) * 2_000_000
        write_wrench_series(path, WrenchSeries(stamps, np.sin(np.arange(n) * 0.01), 'f', '/w'))

        def streaming():
            assert sum(len(t) for t, _ in open_signal(path).blocks()) == n

        def bag_reader(check=True):
            with BagReader(path) as bag:
                assert sum(1 for _ in bag.messages(check=check)) == n

        def rosbags():
            with Reader(path) as reader:
                assert sum(1 for _ in reader.messages()) == n

        rows = [
            ('rosbags Reader.messages (reference)', best(rosbags)),
            ('open_signal (streaming, checked)', best(streaming)),
            ('BagReader.messages(check=False)', best(lambda: bag_reader(False))),
            ('BagReader.messages (checked + CDR decode)', best(bag_reader)),
        ]
    print(f'{n} WrenchStamped messages, best of 3:')
    for name, seconds in rows:
        print(f'  {name:<44} {seconds * 1e3:8.0f} ms  {seconds / n * 1e6:6.2f} us/message')


if __name__ == '__main__':
    main()
