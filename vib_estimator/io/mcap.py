# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The package's one MCAP reader: records, the summary's indexes, and checked chunks.

MCAP (https://mcap.dev/spec) is a sequence of records ``opcode (u8) | length (u64) | body`` between
two magic strings; chunks hold (usually compressed) schema, channel and message records; each chunk
is followed by one message index per channel (log time -> offset of the message record in the
chunk), and the summary section at the end lists the channels and one chunk index per chunk.

Three users, one set of primitives (:class:`Fields`, :func:`records`, :func:`chunk_records`):

* the streaming fast path (:mod:`.streaming`): :func:`read_plan` locates a topic's chunks by the
  summary, :func:`read_chunk` reads one chunk and its message indexes into numpy arrays;
* the bag reader of the replayer and ``read_wrench_series`` (:mod:`.bags`): :func:`iter_messages`,
  every message of some topics in log-time order across chunks;
* ``vib-estimator reindex`` (:mod:`.reindex`): a scan of every complete record of a cut file.

Integrity. A chunk whose checksum (``uncompressed_crc``, when the writer set it) does not match, or
that does not decompress to its stated size, is *damaged*: none of its messages is used. A message
index entry that does not point at a whole message record of its channel and log time is damaged
too (and two entries at one offset give one message). Damaged records are counted in
:class:`ChunkMessages.skipped`, never raised: the callers count, report and (``strict``) refuse.
So a damaged file never yields more messages than the intact one. Anything else wrong with the
layout (no summary, a summary that does not parse) is :class:`McapFormatError`: the caller reads
the file another way (``rosbags``) or reports it.
"""

from __future__ import annotations

import heapq
import io
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Collection, Dict, Iterator, List, Optional, Sequence, Tuple

import numpy as np
from rosbags.rosbag2.storage_mcap import DECOMPRESSORS

from ..errors import McapCut, McapFormatError
from .cdr import gather

MAGIC = b'\x89MCAP0\r\n'
OP_HEADER, OP_FOOTER, OP_SCHEMA, OP_CHANNEL, OP_MESSAGE = 0x01, 0x02, 0x03, 0x04, 0x05
OP_CHUNK, OP_MESSAGE_INDEX, OP_CHUNK_INDEX, OP_DATA_END = 0x06, 0x07, 0x08, 0x0F
#: opcode (1) + length (8) of every record
RECORD_HEAD = 1 + 8
#: the footer record: head + summary start (8) + summary offset start (8) + summary CRC (4)
FOOTER_BYTES = RECORD_HEAD + 8 + 8 + 4
#: the fields of a message record before its payload: channel (2), sequence (4), log time (8),
#: publish time (8)
MESSAGE_HEAD = 2 + 4 + 8 + 8
#: byte of a chunk record at which its CRC-32 is: after the head, message start and end times and
#: the uncompressed size
CHUNK_CRC_AT = RECORD_HEAD + 8 + 8 + 8
#: a message index entry: log time (u64), record offset in the chunk (u64)
INDEX_ENTRY = np.dtype([('t', '<u8'), ('o', '<u8')])


class Fields:
    """Little-endian fields of a record body ``data[pos:end]``, read in order; :class:`McapCut`
    when one runs past ``end``."""

    def __init__(self, data: bytes, pos: int = 0, end: Optional[int] = None) -> None:
        self.data, self.pos = data, pos
        self.end = len(data) if end is None else min(end, len(data))

    def take(self, n: int) -> bytes:
        if n < 0 or self.pos + n > self.end:
            raise McapCut()
        self.pos += n
        return self.data[self.pos - n : self.pos]

    def uint(self, size: int) -> int:
        return int.from_bytes(self.take(size), 'little')

    def string(self) -> str:
        try:
            return self.take(self.uint(4)).decode()
        except UnicodeDecodeError:
            raise McapFormatError('a string field is not UTF-8') from None

    def sized(self, size: int = 4) -> Tuple[int, int]:
        """``(start, length)`` of a length-prefixed byte array (length: ``size`` bytes)."""
        length = self.uint(size)
        self.take(length)
        return self.pos - length, length

    def rest(self) -> bytes:
        return self.data[self.pos : self.end]


def records(data: bytes, pos: int, end: int) -> Iterator[Tuple[int, Fields]]:
    """``(opcode, fields of the body)`` of each record in ``data[pos:end]``; at the first one cut
    short, :class:`McapCut` with ``args`` (its start[, opcode, start of its body])."""
    end = min(end, len(data))
    while pos < end:
        head = Fields(data, pos, end)
        try:
            op, length = head.uint(1), head.uint(8)
        except McapCut:
            raise McapCut(pos) from None
        if head.pos + length > end:
            raise McapCut(pos, op, head.pos)
        yield op, Fields(data, head.pos, head.pos + length)
        pos = head.pos + length


def read_schema(body: Fields) -> Tuple[int, str, str, bytes]:
    """``(id, name, encoding, data)`` of a schema record."""
    sid = body.uint(2)
    name, encoding = body.string(), body.string()
    return sid, name, encoding, body.take(body.uint(4))


def read_channel(body: Fields) -> Tuple[int, int, str, Dict[str, str]]:
    """``(id, schema id, topic, metadata)`` of a channel record."""
    cid, sid, topic, _encoding = body.uint(2), body.uint(2), body.string(), body.string()
    meta = Fields(body.take(body.uint(4)))
    metadata = {}
    while meta.pos < meta.end:
        key = meta.string()
        metadata[key] = meta.string()
    return cid, sid, topic, metadata


def read_message(body: Fields) -> Tuple[int, int, bytes]:
    """``(channel id, log time, payload)`` of a message record."""
    cid, _seq, log_time, _publish = body.uint(2), body.uint(4), body.uint(8), body.uint(8)
    return cid, log_time, body.rest()


def decompress(kind: str, data: bytes, size: int, crc: int) -> Optional[bytes]:
    """A chunk's records: decompressed, checked against its size and (if set) its CRC-32; None if
    damaged. :class:`McapFormatError` for a compression this reader does not know."""
    if kind not in DECOMPRESSORS:
        raise McapFormatError(f'MCAP chunk compression {kind!r} is not supported')
    try:
        raw = DECOMPRESSORS[kind](data, size)
    except Exception:  # noqa: BLE001 -- lz4/zstd raise their own errors on damaged data
        return None
    if len(raw) != size or (crc and zlib.crc32(raw) != crc):
        return None
    return raw


def chunk_records(body: Fields) -> Tuple[Optional[bytes], str]:
    """The records of a whole chunk record's body (None if damaged) and its compression."""
    body.take(16)  # message start and end time
    size, crc, kind = body.uint(8), body.uint(4), body.string()
    start, length = body.sized(8)
    return decompress(kind, body.data[start : start + length], size, crc), kind


# ------------------------------------------------------------------------------- the summary


@dataclass(frozen=True)
class ChunkRead:
    """One chunk to read: file, where, its message indexes ``(channel, offset, length)`` for the
    channels asked for, and the span of its messages' log times."""

    path: Path
    start: int
    length: int
    index_offsets: Tuple[Tuple[int, int, int], ...]
    first_ns: int
    last_ns: int


@dataclass
class Summary:
    """What the summary section of one MCAP file says: channel topics, and chunk indexes as
    ``(first_ns, last_ns, offset, length, {channel: (index offset, index length)})``."""

    path: Path
    topics: Dict[int, str]
    chunks: List[Tuple[int, int, int, int, Dict[int, Tuple[int, int]]]]

    def channels_of(self, topics: Collection[str]) -> List[int]:
        return sorted(c for c, t in self.topics.items() if t in topics)

    def chunk_reads(self, channels: Collection[int]) -> List[ChunkRead]:
        """The chunks holding messages of ``channels``; McapFormatError for a chunk without
        message indexes (then only a scan finds its messages)."""
        selected = []
        for first, last, start, length, indexes in self.chunks:
            wanted = tuple((c, *indexes[c]) for c in sorted(channels) if c in indexes)
            if wanted:
                selected.append(ChunkRead(self.path, start, length, wanted, first, last))
            elif not indexes:
                raise McapFormatError(f'{self.path}: a chunk has no message index')
        return selected


def _summary_bytes(handle, path: Path) -> bytes:
    handle.seek(0, io.SEEK_END)
    size = handle.tell()
    if size < 2 * len(MAGIC) + FOOTER_BYTES:
        raise McapFormatError(f'{path}: too short for an indexed MCAP file')
    handle.seek(size - len(MAGIC) - FOOTER_BYTES)
    tail = handle.read(len(MAGIC) + FOOTER_BYTES)
    if tail[-len(MAGIC) :] != MAGIC or tail[0] != OP_FOOTER:
        raise McapFormatError(f'{path}: no MCAP footer')
    summary_start = int.from_bytes(tail[RECORD_HEAD : RECORD_HEAD + 8], 'little')
    summary_end = size - len(MAGIC) - FOOTER_BYTES
    if not len(MAGIC) <= summary_start <= summary_end:
        raise McapFormatError(f'{path}: no summary section')
    handle.seek(summary_start)
    return handle.read(summary_end - summary_start)


def _chunk_index(body: Fields):
    """A chunk index record: its span, where the chunk is, and where each message index is (the
    length of one index is up to the next one, or the end of them all)."""
    first, last, start, length = (body.uint(8) for _ in range(4))
    table = Fields(body.data, *_span(body.sized(4)))
    entries = []
    while table.pos < table.end:
        entries.append((table.uint(2), table.uint(8)))
    index_length = body.uint(8)
    by_offset = sorted(off for _, off in entries)
    ends = dict(zip(by_offset, by_offset[1:] + [start + length + index_length]))
    return first, last, start, length, {ch: (off, ends[off] - off) for ch, off in entries}


def _span(sized: Tuple[int, int]) -> Tuple[int, int]:
    start, length = sized
    return start, start + length


def read_summary(path: Path) -> Summary:
    """The summary of an MCAP file; McapFormatError if it has none that parses, or lists no
    channel (channels only in the data section: the file must be scanned)."""
    path = Path(path)
    with path.open('rb') as handle:
        data = _summary_bytes(handle, path)
    topics: Dict[int, str] = {}
    chunks = []
    try:
        for op, body in records(data, 0, len(data)):
            if op == OP_CHANNEL:
                cid, _sid, topic, _meta = read_channel(body)
                topics[cid] = topic
            elif op == OP_CHUNK_INDEX:
                chunks.append(_chunk_index(body))
    except McapCut:
        raise McapFormatError(f'{path}: the summary section is damaged') from None
    if not topics:
        raise McapFormatError(f'{path}: the summary lists no channel')
    return Summary(path, topics, chunks)


def read_plan(files: Sequence[Path], topic: str) -> List[ChunkRead]:
    """Every chunk of ``files`` holding ``topic``, in log-time order; McapFormatError if they
    overlap in time (then the messages must be merged, not read chunk after chunk)."""
    chunks = []
    for path in files:
        summary = read_summary(path)
        chunks.extend(summary.chunk_reads(summary.channels_of({topic})))
    chunks.sort(key=lambda c: (c.first_ns, c.last_ns))
    for before, after in zip(chunks, chunks[1:]):
        if after.first_ns < before.last_ns:
            raise McapFormatError(f'{after.path}: chunks overlap in time')
    return chunks


# ------------------------------------------------------------------------------- one chunk


@dataclass
class ChunkMessages:
    """The messages of a chunk for the channels asked for, in log-time order: the chunk's records
    (uint8), each payload's offset and length in them, log times, channels; ``skipped``: message
    index entries not used because the chunk or the entry is damaged (``damage`` says how)."""

    records: np.ndarray
    offsets: np.ndarray
    lengths: np.ndarray
    log_times: np.ndarray
    channels: np.ndarray
    skipped: int = 0
    damage: str = ''

    def payloads(self) -> Iterator[Tuple[int, int, bytes]]:
        """``(channel, log time, payload bytes)`` of each message."""
        raw = self.records.tobytes()
        for ch, t, off, size in zip(
            self.channels.tolist(),
            self.log_times.tolist(),
            self.offsets.tolist(),
            self.lengths.tolist(),
        ):
            yield ch, t, raw[off : off + size]


def _empty(skipped: int, damage: str) -> ChunkMessages:
    none = np.empty(0, np.int64)
    return ChunkMessages(np.empty(0, np.uint8), none, none, none, none, skipped, damage)


def _index_entries(handle, chunk: ChunkRead) -> Tuple[np.ndarray, np.ndarray, int]:
    """The entries of the chunk's message indexes and their channels; and how many index records
    are damaged (not a message index of their channel)."""
    entries, channels, damaged = [], [], 0
    for channel, offset, length in chunk.index_offsets:
        handle.seek(offset)
        record = handle.read(length)
        body = Fields(record, RECORD_HEAD)
        try:
            if record[:1] != bytes([OP_MESSAGE_INDEX]) or body.uint(2) != channel:
                raise McapCut()
            start, size = body.sized(4)
        except McapCut:
            damaged += 1
            continue
        part = np.frombuffer(
            record, dtype=INDEX_ENTRY, count=size // INDEX_ENTRY.itemsize, offset=start
        )
        entries.append(part)
        channels.append(np.full(len(part), channel, np.int64))
    if not entries:
        return np.empty(0, INDEX_ENTRY), np.empty(0, np.int64), damaged
    return np.concatenate(entries), np.concatenate(channels), damaged


def _valid_entries(
    records: np.ndarray,
    index: np.ndarray,
    channels: np.ndarray,
    base: np.ndarray,
    size: np.ndarray,
) -> Tuple[np.ndarray, np.ndarray]:
    """Which index entries point at a whole message record of their channel and log time inside
    their chunk's records (``records[base:base + size]``, per entry), and the length of each such
    record (a gather of each field of the records' heads)."""
    head = RECORD_HEAD + MESSAGE_HEAD - 8  # up to the end of the log time
    room = np.maximum(size - RECORD_HEAD - MESSAGE_HEAD, -1)
    ok = (room >= 0) & (index['o'] <= np.maximum(room, 0).astype(np.uint64))
    if not ok.any():
        return ok, np.zeros(len(index), np.int64)
    at = base + np.where(ok, index['o'], 0).astype(np.int64)
    length = gather(records, at + 1, '<u8')
    ok &= records[at] == OP_MESSAGE
    ok &= (length >= MESSAGE_HEAD) & (length <= size.astype(np.uint64))
    length = np.where(ok, length, 0).astype(np.int64)
    ok &= at + RECORD_HEAD + length <= base + size
    ok &= gather(records, at + RECORD_HEAD, '<u2') == channels
    ok &= gather(records, at + head - 8, '<u8') == index['t']
    return ok, length


def _chunk_content(handle, chunk: ChunkRead) -> Optional[bytes]:
    """The records of ``chunk`` (None if the chunk is damaged: checksum, size, compression)."""
    handle.seek(chunk.start)
    raw = handle.read(chunk.length)
    try:
        head = Fields(raw)
        if head.uint(1) == OP_CHUNK:
            return chunk_records(Fields(raw, RECORD_HEAD, RECORD_HEAD + head.uint(8)))[0]
    except (McapCut, McapFormatError):
        pass
    return None


def read_chunk(handle, chunk: ChunkRead) -> ChunkMessages:
    """The messages of ``chunk`` (see :class:`ChunkMessages`); a damaged chunk gives none, all of
    its index entries counted as skipped."""
    return read_chunks(handle, [chunk])


def read_chunks(handle, chunks: Sequence[ChunkRead]) -> ChunkMessages:
    """The messages of several chunks read together, chunk after chunk, each in log-time order:
    one :class:`ChunkMessages` whose records are the chunks' records joined. One validation, sort
    and gather for all: a recorder's 64 KiB chunks hold ~600 messages each, and reading them one
    by one costs more in numpy's per-call overhead than in the work. ``skipped`` sums the chunks'
    damaged records; ``damage`` says, per damaged chunk, how."""
    contents, indexes, owners = [], [], []
    damages: Dict[int, str] = {}  # per chunk, how it is damaged
    damaged = np.zeros(len(chunks), np.int64)
    for k, chunk in enumerate(chunks):
        index, channels, bad = _index_entries(handle, chunk)
        content = _chunk_content(handle, chunk)
        if content is None:
            damaged[k] = len(index) + bad
            damages[k] = (
                f'chunk at byte {chunk.start} of {chunk.path.name} '
                f'is damaged (checksum, size or compression)'
            )
            continue
        damaged[k] = bad
        contents.append(content)
        indexes.append((index, channels))
        owners.append(k)
    if not contents:
        return _empty(int(damaged.sum()), '; '.join(damages.values()))
    sizes = np.array([len(c) for c in contents], np.int64)
    starts = np.concatenate(([0], np.cumsum(sizes)[:-1]))
    counts = [len(i) for i, _ in indexes]
    which = np.repeat(np.arange(len(contents)), counts)
    index = np.concatenate([i for i, _ in indexes])
    channels = np.concatenate([c for _, c in indexes])
    buf = np.frombuffer(b''.join(contents), np.uint8)
    ok, record_lengths = _valid_entries(buf, index, channels, starts[which], sizes[which])
    keep = np.flatnonzero(ok)
    at = starts[which[keep]] + index['o'][keep].astype(np.int64)
    if len(at) > 1 and not np.all(at[1:] > at[:-1]):  # not in record order: drop repeats
        keep = keep[np.unique(at, return_index=True)[1]]
    keep = keep[np.lexsort((index['t'][keep], which[keep]))]  # by chunk, then log time
    rec = starts[which[keep]] + index['o'][keep].astype(np.int64)
    lost = np.bincount(which, minlength=len(contents)) - np.bincount(
        which[keep], minlength=len(contents)
    )
    for k, count in zip(owners, lost.tolist()):
        damaged[k] += count
        if count:
            damages[k] = (
                f'{count} message index entries of the chunk at byte {chunks[k].start} of '
                f'{chunks[k].path.name} do not point at a message'
            )
    return ChunkMessages(
        buf,
        rec + RECORD_HEAD + MESSAGE_HEAD,
        record_lengths[keep] - MESSAGE_HEAD,
        index['t'][keep].astype(np.int64),
        channels[keep],
        int(damaged.sum()),
        '; '.join(damages[k] for k in sorted(damages)),
    )


# ------------------------------------------------------------------------------- many chunks


def iter_messages(
    path: Path, topics: Collection[str], start_ns: Optional[int] = None, on_skip=None
) -> Iterator[Tuple[str, int, bytes]]:
    """``(topic, log time, payload)`` of every message of ``topics`` in one indexed MCAP file, in
    log-time order (ties: in file order), from ``start_ns`` on; chunks are read lazily, only as
    many at once as overlap in time. ``on_skip(count, damage)`` is called for each chunk with
    damaged records. McapFormatError (before any message) if the file is not indexed."""
    summary = read_summary(path)
    names = summary.topics
    chunks = sorted(
        (
            c
            for c in summary.chunk_reads(summary.channels_of(set(topics)))
            if start_ns is None or c.last_ns >= start_ns
        ),
        key=lambda c: (c.first_ns, c.start),
    )
    return _merged(path, chunks, names, start_ns, on_skip)


def _chunk_messages(
    handle, chunk: ChunkRead, names: Dict[int, str], start_ns, on_skip
) -> Iterator[Tuple[int, str, bytes]]:
    """``(log time, topic, payload)`` of one chunk's messages from ``start_ns`` on."""
    messages = read_chunk(handle, chunk)
    if messages.skipped and on_skip is not None:
        on_skip(messages.skipped, messages.damage)
    for channel, log_time, payload in messages.payloads():
        if start_ns is None or log_time >= start_ns:
            yield log_time, names[channel], payload


def _merged(path: Path, chunks: List[ChunkRead], names: Dict[int, str], start_ns, on_skip):
    with Path(path).open('rb') as handle:
        if all(b.first_ns > a.last_ns for a, b in zip(chunks, chunks[1:])):
            for chunk in chunks:  # one after the other: no merge needed
                for log_time, topic, payload in _chunk_messages(
                    handle, chunk, names, start_ns, on_skip
                ):
                    yield topic, log_time, payload
            return
        heap: List[Tuple[int, int, str, bytes]] = []
        order, i = 0, 0
        while i < len(chunks) or heap:
            while i < len(chunks) and (not heap or chunks[i].first_ns <= heap[0][0]):
                for log_time, topic, payload in _chunk_messages(
                    handle, chunks[i], names, start_ns, on_skip
                ):
                    heapq.heappush(heap, (log_time, order, topic, payload))
                    order += 1
                i += 1
            if heap:
                log_time, _, topic, payload = heapq.heappop(heap)
                yield topic, log_time, payload
