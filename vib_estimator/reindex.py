"""``vib-estimator reindex BAG``: rebuild a bag's ``metadata.yaml`` from its storage files.

Like ``ros2 bag reindex``, for a bag whose recorder was killed or whose ``metadata.yaml`` is lost;
a last MCAP file cut short is repaired first (see :mod:`vib_estimator.io.reindex`). Prints what it
found and what was cut; a directory it cannot reindex gives one ``error:`` line and exit code 2.
"""
from __future__ import annotations

import argparse
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('bag', help='rosbag2 directory of .mcap or .db3 files')


def run(args: argparse.Namespace) -> int:
    from .io.bags import BagError
    from .io.reindex import reindex

    try:
        result = reindex(args.bag)
    except BagError as err:
        print(f'error: {err}', file=sys.stderr)
        return 2
    print(result.summary())
    return 0
