# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Several stamped streams as one: the samples of each stream whose header stamps agree.

The estimator node with ``input_topics`` (several topics of one type) and ``analyze`` / ``survey``
of a bag with several ``--topic`` names read one channel set per topic; a joint estimate needs a
value of every channel at one time. :class:`StampAligner` forms those joint samples, with the
policy of ``message_filters``' approximate-time synchroniser reduced to what sensors that are
sampled together need:

* each stream keeps a queue of its samples in stamp order (a sample not after the stream's previous
  one is skipped: ``skipped_stream_order``; one more than ``jump_ns`` before it -- a bag played
  again, a simulation restarted -- clears every queue and starts over: ``align_resets``);
* while every queue holds a sample, the heads are compared: when they all lie within
  ``tolerance_ns`` of the newest head, they are one joint sample (stamped with the first stream's
  stamp: the first topic is the time base) and leave their queues (``aligned``); otherwise every
  head older than the newest by more than ``tolerance_ns`` can never be matched (its partners on
  the newest head's stream are all later) and is dropped (``dropped_unaligned``);
* a stream that stops (a stalled driver, a dead sensor) lets the others' queues grow up to
  ``depth`` samples each; beyond it the oldest sample is dropped (``dropped_stalled``), so memory
  stays bounded. :meth:`StampAligner.lagging` names the streams whose newest stamp is more than a
  given time behind the newest stream's (the node's diagnostics say so). When the stream resumes,
  the others' samples older than its first new one are dropped as unaligned and joint samples
  flow again; the estimator sees a gap (``max_gap``: a new segment when it is long);
* a message lost on one stream costs the joint sample of its stamp (its partners are dropped as
  unaligned), nothing else.

Every sample pushed is therefore aligned, dropped or skipped (each counted), or still queued
(:attr:`StampAligner.pending`).
"""

from __future__ import annotations

from collections import deque
from typing import Dict, List, Optional, Sequence, Tuple

#: what :class:`StampAligner` counts (the node's diagnostics carry them)
ALIGN_COUNTERS = (
    'aligned',
    'dropped_unaligned',
    'dropped_stalled',
    'skipped_stream_order',
    'align_resets',
)
#: samples kept per stream while waiting for the others (2 s at 1 kHz)
ALIGN_DEPTH = 2000
#: the default stamp tolerance of one joint sample, s (sensors sampled by one driver carry equal
#: stamps; independent ones sampled at 1 kHz within half a period)
ALIGN_TOLERANCE_S = 0.0005


class StampAligner:
    """Joint samples of ``streams`` stamped streams (see the module docstring).

    ``counters``: a dict to count into (:data:`ALIGN_COUNTERS` are added to it when missing), so
    that a caller's counters carry them.
    """

    def __init__(
        self,
        streams: int,
        tolerance_ns: int,
        depth: int = ALIGN_DEPTH,
        counters: Optional[Dict[str, int]] = None,
        jump_ns: Optional[int] = None,
    ):
        if streams < 1:
            raise ValueError(f'need at least one stream, got {streams}')
        if tolerance_ns < 0:
            raise ValueError(f'the stamp tolerance must be >= 0, got {tolerance_ns} ns')
        if depth < 1:
            raise ValueError(f'the queue depth must be >= 1, got {depth}')
        self.tolerance_ns = int(tolerance_ns)
        self.depth = int(depth)
        self.jump_ns = jump_ns
        self.counters = {} if counters is None else counters
        for name in ALIGN_COUNTERS:
            self.counters.setdefault(name, 0)
        self._queues: List[deque] = [deque() for _ in range(streams)]
        self._last: List[Optional[int]] = [None] * streams

    @property
    def streams(self) -> int:
        return len(self._queues)

    @property
    def pending(self) -> int:
        """Samples queued, waiting for the other streams."""
        return sum(len(q) for q in self._queues)

    def push(self, stream: int, stamp: int, values: Sequence[float], tag=None) -> List[Tuple]:
        """Add one sample of ``stream`` (``values``: its channels; ``tag``: anything to hand back
        with it, e.g. the message header); the joint samples it completes, in stamp order, each
        ``(stamp, values of every stream in order, the first stream's tag)``."""
        c = self.counters
        last = self._last[stream]
        if last is not None and stamp <= last:
            if self.jump_ns is None or last - stamp <= self.jump_ns:
                c['skipped_stream_order'] += 1
                return []
            c['align_resets'] += 1
            self.clear()
        self._last[stream] = stamp
        queue = self._queues[stream]
        queue.append((stamp, tuple(values), tag))
        if len(queue) > self.depth:
            queue.popleft()
            c['dropped_stalled'] += 1
        return self._match()

    def _match(self) -> List[Tuple]:
        out = []
        queues, tol, c = self._queues, self.tolerance_ns, self.counters
        while all(queues):
            newest = max(q[0][0] for q in queues)
            stale = [q for q in queues if q[0][0] < newest - tol]
            if stale:
                for q in stale:
                    q.popleft()
                c['dropped_unaligned'] += len(stale)
                continue
            heads = [q.popleft() for q in queues]
            stamp, _, tag = heads[0]
            out.append((stamp, tuple(v for h in heads for v in h[1]), tag))
        c['aligned'] += len(out)
        return out

    def lagging(self, behind_ns: int) -> List[int]:
        """The streams whose newest stamp is more than ``behind_ns`` behind the newest stream's
        (a stream that never sent counts as behind once another has)."""
        known = [s for s in self._last if s is not None]
        if not known:
            return []
        newest = max(known)
        return [i for i, s in enumerate(self._last) if s is None or newest - s > behind_ns]

    def clear(self) -> None:
        """Forget the queued samples and the streams' last stamps (a reset, a time jump)."""
        for q in self._queues:
            q.clear()
        self._last = [None] * len(self._queues)
