# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Streaming readers: a recorded signal as a sequence of numpy blocks, in constant memory.

Three sources, one interface (:func:`open_signal` -> :class:`Signal`, whose ``blocks()`` yields
``(t, y)`` float arrays in recorded order):

* **CSV** (the format of :mod:`.csv_reader`, which also holds its block parser): parsed by
  ``pyarrow.csv``'s streaming reader, one block at a time; a file the fast parser refuses is read
  by the exact :mod:`.csv_reader` rules instead, still block by block.
* **MCAP** (a ``.mcap`` file or a rosbag2 directory of them): the summary's chunk indexes and each
  chunk's message index locate the topic's messages (:mod:`.mcap`); a chunk is read, checked, its
  payloads are decoded at once by :func:`.cdr.decode_fixed`, and the chunk is dropped. Files and
  chunks are read in log-time order; when they overlap in time (or the file has no index) the
  general path below merges the messages instead.
* **Everything else** (sqlite3 ``.db3`` storage, types that are not fixed-layout such as
  ``JointState``, unindexed MCAP): ``rosbags`` iterates the raw messages of every storage file,
  merged in log-time order, and they are decoded in batches (vectorised where the layout allows).

Bags: a topic of one of :data:`.fields.INPUT_TYPES`; time = header stamp (``Float64``,
``Float32``: the log time), relative to the first one (:func:`.fields.seconds_since`), as the node
does. A ``JointState`` message without the joint is skipped and counted (``Signal.skipped``).

Damaged records: a chunk whose checksum fails, an index entry that points at no message, a payload
that does not decode as its type -- each message lost that way is skipped and counted
(``Signal.corrupt``, with the first damage described in ``Signal.damage``); with ``strict`` the
first one raises :class:`~vib_estimator.errors.CorruptRecordError` instead.
Memory is bounded by the block size (``BLOCK_SAMPLES`` samples, one chunk of the file), never by
the length of the recording.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Dict, Iterable, Iterator, List, Optional, Sequence, Tuple

import numpy as np
from rosbags.rosbag2 import Reader

from ..errors import BagError, CdrLayoutError, DamageCount, McapFormatError, as_bag_error
from . import cdr, mcap
from .align import StampAligner
from .bags import TYPESTORE, check_bag_path, only_topic
from .csv_reader import CSV_SUFFIXES, csv_blocks, csv_layout
from .fields import (
    DEFAULT_COMPONENT,
    DEFAULT_INPUT_TOPIC,
    INPUT_TYPES,
    channels_getter,
    check_component,
    check_components,
    has_header,
    normalise_type,
    seconds_since,
    stamp_ns,
    topic_channels,
)

#: samples per block handed to the estimator (bags: chunks are grouped up to this size)
BLOCK_SAMPLES = 1 << 18
#: messages of an MCAP file read and decoded together, about (whole chunks: :func:`_mcap_batches`)
MCAP_BATCH_MESSAGES = 1 << 15

Block = Tuple[np.ndarray, np.ndarray]


@dataclass
class Signal(DamageCount):
    """An opened recording: where the samples come from and how to stream them.

    ``blocks()`` yields ``(t, y)``: time in s (bags: since the first stamp, ``origin_ns``; CSV: the
    time column as written) and the values (a bag's ``components``: one column each, a sample
    only from a message that has them all). ``skipped`` counts messages without the component
    (``JointState`` without the joint), ``corrupt`` the damaged records skipped (``damage``: the
    first one, described), both known once ``blocks()`` is exhausted. ``strict``: a damaged
    record raises :class:`~vib_estimator.errors.CorruptRecordError` instead.
    """

    path: Path
    label: str
    topic: str = ''
    msgtype: str = ''
    component: str = ''
    components: Tuple[str, ...] = ()
    origin_ns: Optional[int] = None
    skipped: int = 0
    corrupt: int = 0
    damage: str = ''
    strict: bool = False
    _source: Callable[[], Iterator[Block]] = field(default=None, repr=False)

    def blocks(self) -> Iterator[Block]:
        if not self.topic:
            yield from self._source()
            return
        for stamps, values in self.stamped():
            if self.origin_ns is None:
                self.origin_ns = int(stamps[0])
            yield seconds_since(stamps, self.origin_ns), values

    def stamped(self) -> Iterator[Block]:
        """A bag topic's non-empty blocks as ``(stamps in ns, values)``."""
        for stamps, values in self._source():
            if len(stamps):
                yield stamps, values


def is_csv(path) -> bool:
    return Path(path).suffix.lower() in CSV_SUFFIXES


def open_signal(
    path,
    topic: Optional[str] = None,
    component: Optional[str] = None,
    column: Optional[str] = None,
    strict: bool = False,
    components: Optional[Sequence[str]] = None,
    info: Optional[BagInfo] = None,
) -> Signal:
    """Open a CSV file or a bag for streaming; raises CsvError, BagError or ValueError (bad
    component) before any sample is read. ``components`` (bags): several fields of the topic,
    the columns of each block's values. ``info``: the bag's :func:`bag_info`, if already read."""
    path = Path(path)
    if is_csv(path):
        return csv_signal(path, column)
    return bag_signal(path, topic, component, strict, components, info)


def csv_signal(path: Path, column: Optional[str]) -> Signal:
    layout = csv_layout(path, column)
    return Signal(path, layout.name, _source=lambda: csv_blocks(layout, BLOCK_SAMPLES))


# ----------------------------------------------------------------------------------------- bags


def open_rosbags(path: Path):
    """An open ``rosbags`` reader of ``path``; BagError (with the reindex hint) if it is none."""
    check_bag_path(path)
    with as_bag_error(path, 'open bag'):
        reader = Reader(path)
        reader.open()
    return reader


@dataclass(frozen=True)
class BagInfo:
    """What a bag's metadata says, read once: ``{topic: full type name}`` in the bag's order,
    its storage files (see :func:`_storage_files`) and each topic's message count."""

    topics: Dict[str, str]
    files: List[Path]
    counts: Dict[str, int]


def bag_info(path) -> BagInfo:
    """The :class:`BagInfo` of the bag ``path`` (BagError if it is none)."""
    path = Path(path)
    reader = open_rosbags(path)
    try:
        counts: Dict[str, int] = {}
        for c in reader.connections:
            counts[c.topic] = counts.get(c.topic, 0) + c.msgcount
        return BagInfo(
            {c.topic: normalise_type(c.msgtype) for c in reader.connections},
            _storage_files(reader, path),
            counts,
        )
    finally:
        reader.close()


def bag_topics(path) -> Dict[str, str]:
    """``{topic: full type name}`` of the bag's topics, in the bag's order."""
    return bag_info(path).topics


def supported_topics(topics: Dict[str, str]) -> Dict[str, str]:
    """The topics of an input type (:data:`.fields.INPUT_TYPES`)."""
    return {name: kind for name, kind in topics.items() if kind in INPUT_TYPES}


def choose_topic(path: Path, topics: Dict[str, str], topic: Optional[str]) -> str:
    """``topic`` checked against the bag, or the bag's only topic of a supported type."""
    listing = ', '.join(f'{n} ({k})' for n, k in topics.items()) or 'none'
    if topic is None:
        candidates = supported_topics(topics)
        if len(candidates) > 1 and '/' + DEFAULT_INPUT_TOPIC in candidates:
            return '/' + DEFAULT_INPUT_TOPIC  # what estimator_node subscribes to by default
        return only_topic(
            path,
            [f'{n} ({k})' for n, k in candidates.items()],
            'input-type',
            listing,
            f' with --topic, e.g. `vib-estimator analyze {path} --topic '
            f'{next(iter(candidates), "")}`',
        )
    if topic not in topics:
        raise BagError(f'bag {path} has no topic {topic!r}; its topics are {listing}')
    if topics[topic] not in INPUT_TYPES:
        raise BagError(
            f'topic {topic} of bag {path} has type {topics[topic]}, not one of '
            f'{", ".join(INPUT_TYPES)}'
        )
    return topic


def bag_signal(
    path: Path,
    topic: Optional[str],
    component: Optional[str],
    strict: bool = False,
    components: Optional[Sequence[str]] = None,
    info: Optional[BagInfo] = None,
) -> Signal:
    """A topic of a bag; ``component`` defaults to the type's ``DEFAULT_COMPONENT``; with
    ``components``, those fields instead (one column each)."""
    info = info or bag_info(path)
    topic = choose_topic(path, info.topics, topic)
    msgtype = info.topics[topic]
    fields = check_components(components, msgtype) if components else ()
    component = check_component(
        fields[0] if fields else component or DEFAULT_COMPONENT[msgtype], msgtype
    )
    files, expected = info.files, info.counts[topic]
    label = f'{topic} {",".join(fields) or component}'
    signal = Signal(path, label, topic, msgtype, component, fields, strict=strict)
    signal._source = lambda: _counted(signal, _bag_blocks(signal, files), expected)
    return signal


@dataclass(frozen=True)
class AlignedTopics:
    """Several topics of a bag read whole and aligned by header stamp (:func:`read_topics`):
    the joint samples' ``stamps`` (ns, the first topic's) and ``values`` (a column per channel,
    topic by topic), the channels' names (``topic:field``), each topic's :class:`Signal` (its
    skipped and damaged records) and the aligner's counters (:data:`.align.ALIGN_COUNTERS`)."""

    stamps: np.ndarray
    values: np.ndarray
    channels: Tuple[str, ...]
    signals: Tuple[Signal, ...]
    counters: Dict[str, int]


def read_topics(
    path,
    topics: Sequence[str],
    component: Optional[str],
    components: Optional[Sequence[str]],
    tolerance_ns: int,
    strict: bool = False,
    info: Optional[BagInfo] = None,
) -> AlignedTopics:
    """The fields (``components``, else ``component``, else each type's default) of each of the
    bag's ``topics``, their samples aligned by stamp as the node aligns its ``input_topics``
    (:class:`.align.StampAligner`, fed in stamp order; raises BagError or ValueError)."""
    path = Path(path)
    info = info or bag_info(path)
    signals = tuple(bag_signal(path, t, component, strict, components, info) for t in topics)
    fields = signals[0].components or (signals[0].component,)
    if any((s.components or (s.component,)) != fields for s in signals):
        raise ValueError(
            f'the topics {", ".join(topics)} default to different fields: give --component(s)'
        )
    stamps, values, source = [], [], []
    for i, signal in enumerate(signals):
        for st, v in signal.stamped():
            stamps.append(st.astype(np.int64))
            values.append(np.asarray(v, dtype=np.float64).reshape(len(st), -1))
            source.append(np.full(len(st), i))
    m = len(fields)
    names = topic_channels([s.topic for s in signals], fields)
    if not stamps:
        return AlignedTopics(
            np.empty(0, np.int64), np.empty((0, m * len(topics))), names, signals, {}
        )
    st, v, src = np.concatenate(stamps), np.concatenate(values), np.concatenate(source)
    order = np.lexsort((src, st))  # by stamp, the topics in their order at equal stamps
    aligner = StampAligner(len(topics), tolerance_ns, depth=len(st))
    out = []
    for k in order.tolist():
        out.extend(aligner.push(int(src[k]), int(st[k]), v[k]))
    joint_stamps = np.array([o[0] for o in out], dtype=np.int64)
    joint = np.array([o[1] for o in out], dtype=np.float64).reshape(len(out), m * len(topics))
    return AlignedTopics(joint_stamps, joint, names, signals, dict(aligner.counters))


def _storage_files(reader, path: Path) -> List[Path]:
    """The storage files of an open bag, in its order; the bag itself when whole files or messages
    are compressed (then only rosbags, which decompresses them, reads it)."""
    storages = getattr(reader.storage, 'storages', None)
    if storages is None or reader.compression_mode in ('file', 'message'):
        return [path]
    return [Path(storage.path) for storage in storages]


def _bag_blocks(signal: Signal, files: List[Path]) -> Iterator[Block]:
    with as_bag_error(signal.path, f'decode {signal.topic} in'):
        plan = None
        if cdr.is_fixed_layout(signal.msgtype) and all(f.suffix == '.mcap' for f in files):
            try:
                plan = mcap.read_plan(files, signal.topic)
            except McapFormatError:
                plan = None
        batches = (
            _mcap_batches(plan, signal) if plan is not None else _rosbags_batches(files, signal)
        )
        yield from _group(_decode(batches, signal))


def _counted(signal: Signal, blocks: Iterator[Block], expected: int) -> Iterator[Block]:
    """``blocks``; at their end, the messages the bag's statistics count but no read found (a
    damaged index or summary) are counted as damaged records too."""
    read = 0
    for block in blocks:
        read += len(block[0])
        yield block
    missing = expected - read - signal.skipped - signal.corrupt
    signal.count_damage(
        max(missing, 0),
        f'{missing} messages of {signal.topic} counted by the bag were not found in it',
    )


def _group(blocks: Iterable[Block]) -> Iterator[Block]:
    """Blocks joined up to ``BLOCK_SAMPLES`` samples (fewer estimator calls, bounded memory)."""
    pending: List[Block] = []
    size = 0
    for block in blocks:
        pending.append(block)
        size += len(block[0])
        if size >= BLOCK_SAMPLES:
            yield tuple(np.concatenate(part) for part in zip(*pending))
            pending, size = [], 0
    if pending:
        yield tuple(np.concatenate(part) for part in zip(*pending))


def _decode(batches, signal: Signal) -> Iterator[Block]:
    """(stamps_ns, values) of each raw batch (buf, offsets, lengths, log_times)."""
    getter = None
    fields = signal.components or (signal.component,)
    for buf, offsets, lengths, log_times in batches:
        if cdr.is_fixed_layout(signal.msgtype):
            try:
                columns = [
                    cdr.decode_fixed(buf, offsets, lengths, signal.msgtype, c) for c in fields
                ]
                stamps = columns[0][0]
                values = (
                    np.column_stack([v for _, v in columns])
                    if signal.components
                    else columns[0][1]
                )
                yield (log_times if stamps is None else stamps), values
                continue
            except CdrLayoutError:
                pass
        getter = getter or channels_getter(fields, signal.msgtype)
        yield _decode_general(buf, offsets, lengths, log_times, signal, getter)


def _decode_general(buf, offsets, lengths, log_times, signal: Signal, getter) -> Block:
    """The rosbags deserialiser, message by message (JointState, big-endian CDR, ...); a payload
    that does not decode as its type is a damaged record."""
    stamps: List[int] = []
    values: list = []
    several = len(signal.components)
    stamped = has_header(signal.msgtype)  # (once: not per message)
    raw = buf.tobytes() if isinstance(buf, np.ndarray) else buf
    for off, size, log_time in zip(offsets.tolist(), lengths.tolist(), log_times.tolist()):
        try:
            msg = TYPESTORE.deserialize_cdr(raw[off : off + size], signal.msgtype)
            value = getter(msg)
            stamp = stamp_ns(msg.header) if stamped else log_time
        except Exception as err:  # noqa: BLE001 -- rosbags raises what its parsing step does
            signal.count_damage(
                1,
                f'a {signal.topic} message logged at {log_time} ns does not '
                f'decode as {signal.msgtype} ({type(err).__name__})',
            )
            continue
        if value is None:
            signal.skipped += 1
            continue
        stamps.append(stamp)
        values.append(value if several else float(value))
    shape = (len(values), several) if several else (len(values),)
    return np.array(stamps, dtype=np.int64), np.array(values, dtype=np.float64).reshape(shape)


def _rosbags_batches(files: List[Path], signal: Signal, size: int = 1 << 16):
    """Raw messages of the topic from every storage file, merged by log time, in batches."""
    readers = []
    try:
        streams = []
        for path in files:
            reader = Reader(path)
            reader.open()
            readers.append(reader)
            conns = [c for c in reader.connections if c.topic == signal.topic]
            if conns:
                streams.append(((t, i, d) for i, (_, t, d) in enumerate(reader.messages(conns))))
        batch: List[Tuple[int, int, bytes]] = []
        for item in heapq.merge(*streams, key=lambda m: m[0]):
            batch.append(item)
            if len(batch) == size:
                yield _pack(batch)
                batch = []
        if batch:
            yield _pack(batch)
    finally:
        for reader in readers:
            reader.close()


def _pack(batch) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    datas = [bytes(m[2]) for m in batch]
    lengths = np.fromiter(map(len, datas), dtype=np.int64, count=len(datas))
    offsets = np.concatenate(([0], np.cumsum(lengths)[:-1])).astype(np.int64)
    buf = np.frombuffer(b''.join(datas), dtype=np.uint8)
    return buf, offsets, lengths, np.array([m[0] for m in batch], dtype=np.int64)


def _mcap_batches(plan: List[mcap.ChunkRead], signal: Signal):
    """(buf, payload offsets, lengths, log times) of the topic's messages, consecutive chunks of
    a file read together up to about :data:`MCAP_BATCH_MESSAGES` messages
    (:func:`.mcap.read_chunks`); the damaged records of each chunk counted."""
    handles: Dict[Path, object] = {}
    try:
        for group in _chunk_groups(plan, MCAP_BATCH_MESSAGES):
            path = group[0].path
            handle = handles.get(path) or handles.setdefault(path, path.open('rb'))
            messages = mcap.read_chunks(handle, group)
            signal.count_damage(messages.skipped, messages.damage)
            if len(messages.offsets):
                yield messages.records, messages.offsets, messages.lengths, messages.log_times
    finally:
        for handle in handles.values():
            handle.close()


def _chunk_groups(plan: List[mcap.ChunkRead], size: int) -> Iterator[List[mcap.ChunkRead]]:
    """Runs of consecutive chunks of one file holding about ``size`` messages (counted from
    their message indexes' lengths: an entry is 16 bytes)."""
    group: List[mcap.ChunkRead] = []
    count = 0
    for chunk in plan:
        if group and (chunk.path != group[0].path or count >= size):
            yield group
            group, count = [], 0
        group.append(chunk)
        count += sum(length for _, _, length in chunk.index_offsets) // mcap.INDEX_ENTRY.itemsize
    if group:
        yield group
