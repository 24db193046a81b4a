# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""io.align.StampAligner: several stamped streams as one."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vib_estimator.io.align import ALIGN_COUNTERS, StampAligner

MS = 1_000_000  # ns


def interleave(streams, order_seed=0):
    """(stream, stamp, values) of every stream's samples, in a shuffled arrival order that keeps
    each stream's own order (as separate topics arrive)."""
    rng = np.random.default_rng(order_seed)
    cursors = [0] * len(streams)
    out = []
    while any(c < len(s) for c, s in zip(cursors, streams)):
        live = [i for i, s in enumerate(streams) if cursors[i] < len(s)]
        i = int(rng.choice(live))
        out.append((i, *streams[i][cursors[i]]))
        cursors[i] += 1
    return out


def run(aligner, arrivals):
    out = []
    for i, stamp, values in arrivals:
        out.extend(aligner.push(i, stamp, values, tag=(i, stamp)))
    return out


def test_equal_stamps_in_any_arrival_order_are_joined_in_stamp_order():
    stamps = [k * MS for k in range(100)]
    streams = [[(s, (float(i), s / MS)) for s in stamps] for i in range(3)]
    aligner = StampAligner(3, 0)
    out = run(aligner, interleave(streams, 4))
    assert [o[0] for o in out] == stamps
    assert all(o[1] == (0.0, s / MS, 1.0, s / MS, 2.0, s / MS) for o, s in zip(out, stamps))
    assert all(o[2] == (0, s) for o, s in zip(out, stamps))  # the first stream's tag
    assert aligner.counters == {**dict.fromkeys(ALIGN_COUNTERS, 0), 'aligned': 100}
    assert aligner.pending == 0


def test_a_lost_message_costs_its_joint_sample_only():
    stamps = [k * MS for k in range(50)]
    lost = {7, 8, 30}
    streams = [
        [(s, (1.0,)) for s in stamps],
        [(s, (2.0,)) for k, s in enumerate(stamps) if k not in lost],
    ]
    aligner = StampAligner(2, 0)
    out = run(aligner, interleave(streams, 1))
    assert [o[0] for o in out] == [s for k, s in enumerate(stamps) if k not in lost]
    assert aligner.counters['dropped_unaligned'] == len(lost)


def test_stamps_within_the_tolerance_are_one_sample_and_the_first_stream_is_the_time_base():
    base = [k * 10 * MS for k in range(20)]
    jitter = np.random.default_rng(2).uniform(-0.4, 0.4, len(base)) * MS
    streams = [[(s, (0.0,)) for s in base], [(s + int(j), (1.0,)) for s, j in zip(base, jitter)]]
    out = run(StampAligner(2, MS // 2), interleave(streams, 3))
    assert [o[0] for o in out] == base
    # beyond the tolerance nothing pairs
    shifted = [[(s, (0.0,)) for s in base], [(s + 2 * MS, (1.0,)) for s in base]]
    aligner = StampAligner(2, MS)
    assert run(aligner, interleave(shifted, 3)) == []
    assert aligner.counters['dropped_unaligned'] >= len(base) - 1


def test_a_stalled_stream_bounds_the_others_queues_and_is_named_until_it_resumes():
    aligner = StampAligner(2, 0, depth=10)
    for k in range(5):
        aligner.push(0, k * MS, (0.0,))
        aligner.push(1, k * MS, (1.0,))
    for k in range(5, 40):  # stream 1 stalls
        assert aligner.push(0, k * MS, (0.0,)) == []
    assert aligner.pending == 10
    assert aligner.counters['dropped_stalled'] == 35 - 10
    assert aligner.lagging(20 * MS) == [1] and aligner.lagging(40 * MS) == []
    out = aligner.push(1, 39 * MS, (1.0,))  # resumes: the older waiting samples can never pair
    assert [o[0] for o in out] == [39 * MS]
    assert aligner.counters['dropped_unaligned'] == 9
    assert aligner.pending == 0 and aligner.lagging(0) == []


def test_out_of_order_samples_are_skipped_and_a_jump_back_starts_over():
    aligner = StampAligner(2, 0, jump_ns=100 * MS)
    aligner.push(0, 10 * MS, (0.0,))
    assert aligner.push(0, 10 * MS, (0.0,)) == []
    assert aligner.push(0, 5 * MS, (0.0,)) == []
    assert aligner.counters['skipped_stream_order'] == 2
    aligner.push(0, 500 * MS, (0.0,))
    assert aligner.push(0, 1 * MS, (0.0,)) == []  # a bag played again: 499 ms back
    assert aligner.counters['align_resets'] == 1 and aligner.pending == 1
    assert [o[0] for o in aligner.push(1, 1 * MS, (1.0,))] == [1 * MS]


@pytest.mark.parametrize(
    'args, message',
    [((0, 0), 'at least one stream'), ((2, -1), 'tolerance'), ((2, 0, 0), 'depth')],
)
def test_bad_arguments(args, message):
    with pytest.raises(ValueError, match=message):
        StampAligner(*args)


@settings(max_examples=60, deadline=None)
@given(
    streams=st.integers(1, 4),
    n=st.integers(0, 60),
    loss=st.floats(0.0, 0.5),
    tolerance=st.integers(0, 3),
    depth=st.integers(1, 20),
    seed=st.integers(0, 2**16),
)
def test_every_sample_is_accounted_for(streams, n, loss, tolerance, depth, seed):
    """Aligned (once per stream), dropped, skipped or pending: nothing is lost uncounted; the
    joint samples ascend and their stamps agree within the tolerance."""
    rng = np.random.default_rng(seed)
    data = [
        [(int(k * 10 + rng.integers(-3, 4)), (float(i),)) for k in range(n) if rng.random() > loss]
        for i in range(streams)
    ]
    aligner = StampAligner(streams, tolerance, depth=depth)
    out = []
    for i, stamp, values in interleave(data, seed):
        for o in aligner.push(i, stamp, values):
            out.append(o)
    c = aligner.counters
    pushed = sum(len(d) for d in data)
    accounted = (
        c['aligned'] * streams
        + c['dropped_unaligned']
        + c['dropped_stalled']
        + c['skipped_stream_order']
        + aligner.pending
    )
    assert accounted == pushed and c['aligned'] == len(out)
    assert all(b[0] > a[0] for a, b in zip(out, out[1:]))
    assert all(o[1] == tuple(float(i) for i in range(streams)) for o in out)
