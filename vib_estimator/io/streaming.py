"""Streaming readers: a recorded signal as a sequence of numpy blocks, in constant memory.

Three sources, one interface (:func:`open_signal` -> :class:`Signal`, whose ``blocks()`` yields
``(t, y)`` float arrays in recorded order):

* **CSV** (the format of :mod:`.csv_reader`): parsed by ``pyarrow.csv``'s streaming reader, one
  block of ``CSV_BLOCK_BYTES`` at a time. A file the fast parser refuses (comment lines between the
  data, cells with spaces, ragged rows, a cell that is not a number) is read by the exact
  :mod:`.csv_reader` rules instead, still block by block, so the result and the error messages are
  those of that reader.
* **MCAP** (a ``.mcap`` file or a rosbag2 directory of them): the summary's chunk indexes and each
  chunk's message index locate the topic's messages; a chunk is read, its payloads are decoded at
  once by :func:`.cdr.decode_fixed`, and the chunk is dropped. Files and chunks are read in
  log-time order; when they overlap in time (or the file has no index) the general path below
  merges the messages instead.
* **Everything else** (sqlite3 ``.db3`` storage, types that are not fixed-layout such as
  ``JointState``, unindexed MCAP): ``rosbags`` iterates the raw messages of every storage file,
  merged in log-time order, and they are decoded in batches (vectorised where the layout allows).

Bags: a topic of one of :data:`.fields.INPUT_TYPES`; time = header stamp (``Float64``: the log
time), relative to the first one (:func:`.fields.seconds_since`), as the node does. A
``JointState`` message without the joint is skipped and counted (``Signal.skipped``).
Memory is bounded by the block size (``BLOCK_SAMPLES`` samples, one chunk of the file), never by
the length of the recording.
"""
from __future__ import annotations

import heapq
import io
import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Dict, Iterable, Iterator, List, Optional, Tuple

import numpy as np

from . import cdr
from .csv_reader import csv_layout, iter_csv_rows
from .fields import (DEFAULT_COMPONENT, DEFAULT_INPUT_TOPIC, FLOAT64, INPUT_TYPES,
                     check_component, component_getter, normalise_type, seconds_since, stamp_ns)

#: samples per block handed to the estimator (bags: chunks are grouped up to this size)
BLOCK_SAMPLES = 1 << 18
#: bytes of CSV text per parsed block (512 kB: ~20 k rows). Arrow's streaming reader reads up to
#: 32 blocks ahead on its I/O thread, so this sets the reader's memory (~16 MB in flight; 2 MB
#: blocks held ~70 MB) while larger blocks parse no faster per CPU second
#: (benchmarks/bench_survey.py)
CSV_BLOCK_BYTES = 1 << 19

Block = Tuple[np.ndarray, np.ndarray]


class BagFormatError(Exception):
    """Raised inside the MCAP fast path when the file needs the general reader."""


@dataclass
class Signal:
    """An opened recording: where the samples come from and how to stream them.

    ``blocks()`` yields ``(t, y)``: time in s (bags: since the first stamp, ``origin_ns``; CSV: the
    time column as written) and the values. ``skipped`` counts messages without the component
    (``JointState`` without the joint), known once ``blocks()`` is exhausted.
    """

    path: Path
    label: str
    topic: str = ''
    msgtype: str = ''
    component: str = ''
    origin_ns: Optional[int] = None
    skipped: int = 0
    _source: Callable[[], Iterator[Block]] = field(default=None, repr=False)

    def blocks(self) -> Iterator[Block]:
        if not self.topic:
            yield from self._source()
            return
        for stamps, values in self._source():
            if len(stamps) == 0:
                continue
            if self.origin_ns is None:
                self.origin_ns = int(stamps[0])
            yield seconds_since(stamps, self.origin_ns), values


def is_csv(path) -> bool:
    return Path(path).suffix.lower() in ('.csv', '.txt')


def open_signal(path, topic: Optional[str] = None, component: Optional[str] = None,
                column: Optional[str] = None) -> Signal:
    """Open a CSV file or a bag for streaming; raises CsvError, BagError or ValueError (bad
    component) before any sample is read."""
    path = Path(path)
    if is_csv(path):
        return csv_signal(path, column)
    return bag_signal(path, topic, component)


# ----------------------------------------------------------------------------------------- CSV

def csv_signal(path: Path, column: Optional[str]) -> Signal:
    layout = csv_layout(path, column)
    return Signal(path, layout.name, _source=lambda: _csv_blocks(layout))


def _csv_blocks(layout) -> Iterator[Block]:
    """Blocks by pyarrow; on a file it refuses, the rest by the csv_reader rules (all of it when
    pyarrow is not installed: rosdep alone does not bring it)."""
    try:
        import pyarrow as pa
        import pyarrow.csv as pacsv
    except ImportError:
        yield from _csv_blocks_exact(layout, skip=0)
        return

    names = [f'c{i}' for i in range(layout.width)]
    wanted = [names[0], names[layout.index]]
    done = 0
    try:
        # read by arrow itself, not through a Python file: a Python read allocates a fresh 2 MB
        # bytes object per block, which a process tuned to return memory at once (Dask's nanny
        # sets MALLOC_TRIM_THRESHOLD_) maps and unmaps every time (4x the page faults)
        with pa.OSFile(str(layout.path)) as handle:
            handle.seek(layout.data_offset)
            reader = pacsv.open_csv(
                handle, memory_pool=pa.system_memory_pool(),
                read_options=pacsv.ReadOptions(column_names=names, use_threads=False,
                                                        block_size=CSV_BLOCK_BYTES),
                parse_options=pacsv.ParseOptions(newlines_in_values=False),
                convert_options=pacsv.ConvertOptions(
                    column_types={n: pa.float64() for n in wanted}, include_columns=wanted,
                    null_values=[''], strings_can_be_null=False, quoted_strings_can_be_null=True))
            for batch in reader:
                t, y = (batch.column(i).to_numpy(zero_copy_only=False) for i in range(2))
                done += len(t)
                yield np.asarray(t, np.float64), np.asarray(y, np.float64)
    except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError):
        yield from _csv_blocks_exact(layout, skip=done)


def _csv_blocks_exact(layout, skip: int) -> Iterator[Block]:
    """The csv_reader rules, block by block, after the first ``skip`` data rows."""
    t: List[float] = []
    y: List[float] = []
    for i, (ti, yi) in enumerate(iter_csv_rows(layout)):
        if i < skip:
            continue
        t.append(ti)
        y.append(yi)
        if len(t) == BLOCK_SAMPLES:
            yield np.array(t), np.array(y)
            t, y = [], []
    if t:
        yield np.array(t), np.array(y)


# ----------------------------------------------------------------------------------------- bags

def _bag_error():
    from .bags import BagError
    return BagError


def open_rosbags(path: Path):
    """An open ``rosbags`` reader of ``path``; BagError (with the reindex hint) if it is none."""
    from rosbags.rosbag2 import Reader
    from .bags import _as_bag_error
    BagError = _bag_error()
    if not path.exists():
        raise BagError(f'bag {path} does not exist')
    if path.is_dir() and not (path / 'metadata.yaml').exists():
        raise BagError(f'{path} has no metadata.yaml; if it is a rosbag2 bag, run '
                       f'`vib-estimator reindex {path}` to rebuild it')
    if path.is_file() and path.suffix not in ('.mcap', '.db3'):
        raise BagError(f'{path} is not a bag: expected a .mcap or .db3 file or a rosbag2 '
                       f'directory')
    with _as_bag_error(path, 'open bag'):
        reader = Reader(path)
        reader.open()
    return reader


def bag_topics(path) -> Dict[str, str]:
    """``{topic: full type name}`` of the bag's topics, in the bag's order."""
    reader = open_rosbags(Path(path))
    try:
        return {c.topic: normalise_type(c.msgtype) for c in reader.connections}
    finally:
        reader.close()


def supported_topics(topics: Dict[str, str]) -> Dict[str, str]:
    """The topics of an input type (:data:`.fields.INPUT_TYPES`)."""
    return {name: kind for name, kind in topics.items() if kind in INPUT_TYPES}


def only_topic(path: Path, candidates: List[str], what: str, listing: str, how: str = '') -> str:
    """The one topic of ``candidates`` (shown as they are given), else BagError: none (with the
    bag's ``listing``) or several (choose one, ``how``)."""
    BagError = _bag_error()
    if not candidates:
        raise BagError(f'bag {path} has no {what} topic; its topics are {listing}')
    if len(candidates) > 1:
        raise BagError(f'bag {path} has several {what} topics, choose one{how}: '
                       f'{", ".join(candidates)}')
    return candidates[0].split(' ')[0]


def choose_topic(path: Path, topics: Dict[str, str], topic: Optional[str]) -> str:
    """``topic`` checked against the bag, or the bag's only topic of a supported type."""
    BagError = _bag_error()
    listing = ', '.join(f'{n} ({k})' for n, k in topics.items()) or 'none'
    if topic is None:
        candidates = supported_topics(topics)
        if len(candidates) > 1 and '/' + DEFAULT_INPUT_TOPIC in candidates:
            return '/' + DEFAULT_INPUT_TOPIC       # what estimator_node subscribes to by default
        return only_topic(path, [f'{n} ({k})' for n, k in candidates.items()], 'input-type',
                          listing, f' with --topic, e.g. `vib-estimator analyze {path} --topic '
                          f'{next(iter(candidates), "")}`')
    if topic not in topics:
        raise BagError(f'bag {path} has no topic {topic!r}; its topics are {listing}')
    if topics[topic] not in INPUT_TYPES:
        raise BagError(f'topic {topic} of bag {path} has type {topics[topic]}, not one of '
                       f'{", ".join(INPUT_TYPES)}')
    return topic


def bag_signal(path: Path, topic: Optional[str], component: Optional[str]) -> Signal:
    """A topic of a bag; ``component`` defaults to the type's ``DEFAULT_COMPONENT``."""
    reader = open_rosbags(path)
    try:
        topics = {c.topic: normalise_type(c.msgtype) for c in reader.connections}
        topic = choose_topic(path, topics, topic)
        msgtype = topics[topic]
        component = check_component(component or DEFAULT_COMPONENT[msgtype], msgtype)
        files = _storage_files(reader, path)
    finally:
        reader.close()
    signal = Signal(path, f'{topic} {component}', topic, msgtype, component)
    signal._source = lambda: _bag_blocks(signal, files)
    return signal


def _storage_files(reader, path: Path) -> List[Path]:
    """The storage files of an open bag, in its order; the bag itself when whole files or messages
    are compressed (then only rosbags, which decompresses them, reads it)."""
    storages = getattr(reader.storage, 'storages', None)
    if storages is None or reader.compression_mode in ('file', 'message'):
        return [path]
    return [Path(storage.path) for storage in storages]


def _bag_blocks(signal: Signal, files: List[Path]) -> Iterator[Block]:
    from .bags import _as_bag_error
    with _as_bag_error(signal.path, f'decode {signal.topic} in'):
        plan = None
        if cdr.is_fixed_layout(signal.msgtype) and all(f.suffix == '.mcap' for f in files):
            try:
                plan = _mcap_plan(files, signal.topic)
            except BagFormatError:
                plan = None
        batches = _mcap_batches(plan) if plan is not None else _rosbags_batches(files, signal)
        yield from _group(_decode(batches, signal))


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
    for buf, offsets, lengths, log_times in batches:
        if cdr.is_fixed_layout(signal.msgtype):
            try:
                stamps, values = cdr.decode_fixed(buf, offsets, lengths, signal.msgtype,
                                                  signal.component)
                yield (log_times if stamps is None else stamps), values
                continue
            except cdr.CdrLayoutError:
                pass
        getter = getter or component_getter(signal.component, signal.msgtype)
        yield _decode_general(buf, offsets, lengths, log_times, signal, getter)


def _decode_general(buf, offsets, lengths, log_times, signal: Signal, getter) -> Block:
    """The rosbags deserialiser, message by message (JointState, big-endian CDR, ...)."""
    from .bags import TYPESTORE
    stamps: List[int] = []
    values: List[float] = []
    raw = buf.tobytes() if isinstance(buf, np.ndarray) else buf
    for off, size, log_time in zip(offsets.tolist(), lengths.tolist(), log_times.tolist()):
        msg = TYPESTORE.deserialize_cdr(raw[off:off + size], signal.msgtype)
        value = getter(msg)
        if value is None:
            signal.skipped += 1
            continue
        stamps.append(log_time if signal.msgtype == FLOAT64 else stamp_ns(msg.header))
        values.append(float(value))
    return np.array(stamps, dtype=np.int64), np.array(values, dtype=np.float64)


def _rosbags_batches(files: List[Path], signal: Signal, size: int = 1 << 16):
    """Raw messages of the topic from every storage file, merged by log time, in batches."""
    from rosbags.rosbag2 import Reader
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


# ------------------------------------------------------------------------- MCAP (indexed) fast path

_MAGIC = b'\x89MCAP0\r\n'
_OP_SCHEMA, _OP_CHANNEL, _OP_CHUNK, _OP_CHUNK_INDEX = 0x03, 0x04, 0x06, 0x08


@dataclass(frozen=True)
class _ChunkRead:
    """One chunk to read: file, where, its compression and the message-index records to use."""

    path: Path
    start: int
    length: int
    index_offsets: Tuple[Tuple[int, int], ...]   # (offset, length) of its message indexes
    first_ns: int
    last_ns: int


class _Cursor:
    """Little-endian reads from a bytes object (the MCAP primitives)."""

    def __init__(self, data: bytes, pos: int = 0):
        self.data, self.pos = data, pos

    def take(self, fmt: str):
        values = struct.unpack_from('<' + fmt, self.data, self.pos)
        self.pos += struct.calcsize('<' + fmt)
        return values if len(values) > 1 else values[0]

    def string(self) -> str:
        size = self.take('I')
        self.pos += size
        return self.data[self.pos - size:self.pos].decode()

    def skip_sized(self, fmt: str = 'I') -> Tuple[int, int]:
        size = self.take(fmt)
        self.pos += size
        return self.pos - size, size


def _summary(handle, path: Path) -> bytes:
    """The summary section of an MCAP file (BagFormatError if it has none)."""
    handle.seek(0, io.SEEK_END)
    size = handle.tell()
    if size < 8 + 29 + 8:
        raise BagFormatError(path)
    handle.seek(size - 37)
    tail = handle.read(37)
    if tail[-8:] != _MAGIC or tail[0] != 0x02:
        raise BagFormatError(path)
    summary_start = struct.unpack_from('<Q', tail, 9)[0]
    if summary_start == 0:
        raise BagFormatError(path)
    handle.seek(summary_start)
    return handle.read(size - 37 - summary_start)


def _file_chunks(path: Path, topic: str) -> List[_ChunkRead]:
    """The chunks of one MCAP file that hold messages of ``topic``, by their indexes."""
    with path.open('rb') as handle:
        summary = _summary(handle, path)
    cursor = _Cursor(summary)
    channels = set()
    seen_channels = False
    chunks = []
    while cursor.pos < len(summary):
        op, length = cursor.take('BQ')
        end = cursor.pos + length
        if op == _OP_CHANNEL:
            seen_channels = True
            channel_id, _schema = cursor.take('HH')
            if cursor.string() == topic:
                channels.add(channel_id)
        elif op == _OP_CHUNK_INDEX:
            chunks.append(_chunk_index(cursor, path))
        cursor.pos = end
    if not seen_channels:
        raise BagFormatError(path)         # channels only in the data section: scan instead
    selected = []
    for chunk, index_offsets in chunks:
        wanted = tuple(index_offsets[c] for c in sorted(channels) if c in index_offsets)
        if wanted:
            selected.append(_ChunkRead(path, chunk[2], chunk[3], wanted, chunk[0], chunk[1]))
        elif not index_offsets:
            raise BagFormatError(path)     # a chunk without message indexes
    return selected


def _chunk_index(cursor: _Cursor, path: Path):
    """(start_ns, end_ns, chunk offset, chunk length) and {channel: (offset, length)} of its
    message indexes; the length of one index is up to the next (or the end of all)."""
    head = cursor.take('QQQQ')
    start, size = cursor.skip_sized()
    entries = sorted(struct.unpack_from('<HQ', cursor.data, start + i)
                     for i in range(0, size, 10))
    index_length = cursor.take('Q')
    by_offset = sorted(off for _, off in entries)
    ends = {off: nxt for off, nxt in zip(by_offset, by_offset[1:] + [head[2] + head[3]
                                                                     + index_length])}
    return head, {ch: (off, ends[off] - off) for ch, off in entries}


def _mcap_plan(files: List[Path], topic: str) -> List[_ChunkRead]:
    """Every chunk to read, in log-time order; BagFormatError if they overlap in time."""
    chunks = sorted((c for path in files for c in _file_chunks(path, topic)),
                    key=lambda c: (c.first_ns, c.last_ns))
    for before, after in zip(chunks, chunks[1:]):
        if after.first_ns < before.last_ns:
            raise BagFormatError(after.path)
    return chunks


def _decompress(kind: str, data: bytes, size: int) -> bytes:
    """A chunk's records, by rosbags' own MCAP decompressors (none, lz4, zstd)."""
    from rosbags.rosbag2.storage_mcap import DECOMPRESSORS

    if kind not in DECOMPRESSORS:
        raise ValueError(f'MCAP chunk compression {kind!r} is not supported')
    return DECOMPRESSORS[kind](data, size)


def _mcap_batches(plan: List[_ChunkRead]):
    """(buf, payload offsets, lengths, log times) of the topic's messages, chunk by chunk."""
    handles: Dict[Path, object] = {}
    try:
        for chunk in plan:
            handle = handles.get(chunk.path) or handles.setdefault(chunk.path,
                                                                   chunk.path.open('rb'))
            yield _read_chunk(handle, chunk)
    finally:
        for handle in handles.values():
            handle.close()


def _read_chunk(handle, chunk: _ChunkRead):
    handle.seek(chunk.start)
    raw = handle.read(chunk.length)
    cursor = _Cursor(raw)
    if cursor.take('B') != _OP_CHUNK:
        raise ValueError(f'no chunk record at byte {chunk.start} of {chunk.path}')
    cursor.take('Q')
    _start, _end, uncompressed, _crc = cursor.take('QQQI')
    kind = cursor.string()
    begin, size = cursor.skip_sized('Q')
    records = np.frombuffer(_decompress(kind, raw[begin:begin + size], uncompressed), np.uint8)
    entries = []
    for off, length in chunk.index_offsets:
        handle.seek(off)                     # message indexes follow the chunk
        record = handle.read(length)
        start, size = _Cursor(record, 1 + 8 + 2).skip_sized()
        entries.append(np.frombuffer(record, dtype=[('t', '<u8'), ('o', '<u8')],
                                     count=size // 16, offset=start))
    index = np.concatenate(entries)
    index = index[np.argsort(index['t'], kind='stable')]
    rec = index['o'].astype(np.int64)
    record_len = cdr.gather(records, rec + 1, '<u8').astype(np.int64)
    return records, rec + 31, record_len - 22, index['t'].astype(np.int64)
