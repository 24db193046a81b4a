"""The real flexible-link arm through the node (issue 25): ``flex8.csv`` written as a bag
(:mod:`vib_estimator.io.bags`), replayed by ``bag_replayer`` into ``estimator_node`` with its
default parameters, gives ``vib-estimator analyze``'s floats on the same bag, and those are all
within 2 % of the limit cycle after 4.5 s (``test/analysis/test_real_arm.py`` checks every goal)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from vib_estimator.io.bags import WrenchSeries, write_wrench_series
from vib_estimator.io.csv_reader import read_csv_series

ROOT = Path(__file__).resolve().parents[2]
SHARED = next((p / 'shared' for p in ROOT.parents if (p / 'shared' / 'real-data').is_dir()),
              ROOT.parent / 'shared')
FLEX8 = SHARED / 'real-data' / 'flexible_link_arm' / 'flex8.csv'
EPOCH_NS = 1_700_000_000 * 10 ** 9
LIMIT_CYCLE_HZ = 1.812


@pytest.mark.skipif(not FLEX8.is_file(), reason='../shared/real-data is absent')
def test_recording_replayed_as_a_bag_through_the_node(ros_context, executor, tmp_path,
                                                      monkeypatch, capsys):
    from test_bag_replayer import replay_into_estimator

    from vib_estimator.cli import main
    from vib_estimator.nodes import estimator_node

    s = read_csv_series(FLEX8, column='tip_deflection_m')
    stamps = EPOCH_NS + np.round(s.t * 1e9).astype(np.int64)
    bag = tmp_path / 'flex8'
    write_wrench_series(bag, WrenchSeries(stamps, s.y, 'link', '/coupling_torque'))
    assert main(['analyze', str(bag), '--format', 'jsonl']) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    t = np.array([r['t'] for r in rows])
    offline = [r['frequency_hz'] for r in rows]
    late = np.array(offline)[t >= 4.5]
    assert len(late) >= 5 and np.all(np.abs(late / LIMIT_CYCLE_HZ - 1) <= 0.02)

    # deep input: a stalled executor's burst must not drop samples (see test_bag_replayer)
    monkeypatch.setattr(estimator_node, 'INPUT_DEPTH', len(stamps))
    estimator, online = replay_into_estimator(ros_context, executor, bag, 5.0, len(stamps),
                                              len(offline), timeout=30)
    assert online == offline    # the node publishes analyze's floats
    assert estimator.counters['rejected_inconsistent'] > 0     # the ringing, held back
    estimator.destroy_node()  # off the graph (see test_bag_replayer's looping test)
