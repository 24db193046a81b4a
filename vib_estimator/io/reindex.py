# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``vib-estimator reindex BAG``: rebuild a bag's ``metadata.yaml`` from its storage files
(``ros2 bag reindex``).

:func:`reindex` takes a rosbag2 directory of ``.mcap`` or ``.db3`` files -- one or several (a split
bag), with or without ``metadata.yaml`` -- and writes ``metadata.yaml`` from what the files hold:
topics, types, offered QoS, counts and log-time spans per file. No rclpy import.

A file cut short (the recorder was killed, the disk filled up) is repaired first:

* MCAP: the records are scanned from the start; every complete schema, channel and message --
  also the complete messages of a last, cut, uncompressed chunk -- is kept, and the file is
  rewritten as a complete, indexed MCAP file (written beside it, then renamed over it). What was
  cut is reported: the byte at which the first incomplete record starts and the file's size.
* sqlite3: the database is opened read-write once, so that SQLite rolls back an interrupted
  transaction from its journal (what was committed stays).
"""

from __future__ import annotations

import argparse
import sqlite3
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Optional, Tuple

from rosbags.interfaces import (
    Connection,
    ConnectionExtRosbag2,
    MessageDefinition,
    MessageDefinitionFormat,
)
from rosbags.rosbag2.metadata import parse_qos

from ..errors import BagError, McapCut, McapFormatError, as_bag_error, report
from .bags import (
    METADATA_VERSION,
    TYPESTORE,
    FileStats,
    bag_metadata,
    mcap_file,
    storage_files,
    storage_reader,
    write_metadata,
)
from .mcap import (
    MAGIC,
    OP_CHANNEL,
    OP_CHUNK,
    OP_DATA_END,
    OP_MESSAGE,
    OP_SCHEMA,
    Fields,
    decompress,
    read_channel,
    read_message,
    read_schema,
    records,
)


@dataclass
class McapContent:
    """What the complete records of an MCAP file hold."""

    schemas: Dict[int, Tuple[str, str, bytes]] = field(
        default_factory=dict
    )  # name, encoding, data
    channels: Dict[int, Tuple[str, int, str]] = field(default_factory=dict)  # topic, schema, QoS
    messages: List[Tuple[int, int, bytes]] = field(default_factory=list)  # channel, log time, data
    #: byte at which the first incomplete record starts (the file's size when none is)
    complete_bytes: int = 0
    #: whether the data section is complete (its DataEnd record was read)
    data_end: bool = False
    #: chunks that are damaged (checksum, size or compression): their records are not kept
    damaged_chunks: int = 0


def _read_record(op: int, body: Fields, content: McapContent) -> None:
    """Keep a schema, channel or message record (others carry nothing to rebuild from)."""
    if op == OP_SCHEMA:
        sid, name, encoding, data = read_schema(body)
        content.schemas[sid] = (name, encoding, data)
    elif op == OP_CHANNEL:
        cid, sid, topic, metadata = read_channel(body)
        content.channels[cid] = (topic, sid, metadata.get('offered_qos_profiles', ''))
    elif op == OP_MESSAGE:
        content.messages.append(read_message(body))


def _read_chunk(body: Fields, content: McapContent, cut: bool) -> None:
    """The records of a chunk; of a cut one (``cut``), those complete, if it is uncompressed; of
    a damaged one (CRC, size), only its schemas and channels."""
    keep = None
    body.take(16)  # message start and end time
    size, crc, compression = body.uint(8), body.uint(4), body.string()
    length = body.uint(8)
    if cut:
        if compression:
            return  # a compressed chunk cut short cannot be decoded
        data, start, end = body.data, body.pos, min(body.pos + length, len(body.data))
    else:
        raw = body.take(length)
        data = decompress(compression, raw, size, crc)
        start, end = 0, len(data or raw)
        if data is None:  # damaged: keep its schemas and channels (the rest refers to them)
            content.damaged_chunks += 1
            data = raw if not compression else b''
            keep = (OP_SCHEMA, OP_CHANNEL)
    try:
        for op, inner in records(data, start, min(end, len(data))):
            if keep is None or op in keep:
                _read_record(op, inner, content)
    except (McapCut, McapFormatError):
        pass


def scan_mcap(data: bytes) -> McapContent:
    """The complete schemas, channels and messages of MCAP bytes (possibly cut anywhere)."""
    content = McapContent(complete_bytes=len(data))
    if not data.startswith(MAGIC):
        content.complete_bytes = 0
        return content
    try:
        for op, body in records(data, len(MAGIC), len(data)):
            if op == OP_DATA_END:
                content.data_end = True
                break
            if op == OP_CHUNK:
                _read_chunk(body, content, cut=False)
            else:
                _read_record(op, body, content)
    except McapCut as cut:
        if not cut.args:  # a field past the end of a complete record
            raise BagError('corrupt MCAP data: a record is shorter than its fields') from None
        content.complete_bytes = cut.args[0]
        if len(cut.args) > 1 and cut.args[1] == OP_CHUNK:
            try:
                _read_chunk(Fields(data, cut.args[2]), content, cut=True)
            except McapCut:
                pass  # cut inside the chunk's header
    except McapFormatError as err:
        raise BagError(f'corrupt MCAP data: {err}') from None
    return content


def _connections(content: McapContent) -> Dict[int, Connection]:
    """rosbags connections for the channels of a scanned file (ids kept)."""
    result = {}
    for cid, (topic, sid, qos) in content.channels.items():
        if sid not in content.schemas:
            continue  # its schema was in a damaged chunk: its messages cannot be kept
        name, encoding, definition = content.schemas[sid]
        fmt = MessageDefinitionFormat.IDL if encoding == 'ros2idl' else MessageDefinitionFormat.MSG
        result[cid] = Connection(
            cid,
            topic,
            name,
            MessageDefinition(fmt, definition.decode()),
            '',
            0,
            ConnectionExtRosbag2('cdr', parse_qos(qos)),
            None,
        )
    return result


def repair_mcap(path: Path) -> Optional[str]:
    """Rewrite a cut MCAP file as a complete one; what was cut (None if it was complete)."""
    try:
        storage_reader(path).close()
        return None
    except Exception:  # noqa: BLE001 -- any failure to open: scan it
        pass
    data = path.read_bytes()
    if not data.startswith(MAGIC):
        what = (
            'is empty (0 bytes)'
            if not data
            else (f'does not start with the MCAP magic ({len(data)} bytes)')
        )
        raise BagError(
            f'cannot reindex {path}: it {what}; it is not an MCAP file, so nothing '
            f'can be recovered (left unchanged)'
        )
    content = scan_mcap(data)
    connections = _connections(content)
    writer = mcap_file(path.with_name(path.name + '.tmp'))
    types = set()
    for cid, conn in connections.items():
        if conn.msgtype not in types:
            writer.add_msgtype(conn)
            types.add(conn.msgtype)
        writer.add_connection(conn, content.channels[cid][2])
    lost = 0
    for cid, log_time, payload in content.messages:
        if cid not in connections:
            lost += 1
            continue
        writer.write(connections[cid], log_time, payload)
    writer.close(METADATA_VERSION, '')
    writer.path.replace(path)
    if content.data_end:
        cut = f'summary section cut or damaged (file of {len(data)} bytes)'
    elif content.complete_bytes < len(data):
        cut = (
            f'cut at byte {content.complete_bytes} of {len(data)} (the rest is an incomplete '
            f'record, dropped)'
        )
    else:
        cut = 'not closed (no index)'
    if content.damaged_chunks:
        cut += f'; {content.damaged_chunks} damaged chunk(s) dropped'
    if lost:
        cut += f'; {lost} messages of channels without a schema dropped'
    return f'{path}: {cut}; kept {len(content.messages) - lost} complete messages, index rebuilt'


def recover_sqlite3(path: Path) -> None:
    """Let SQLite roll back an interrupted transaction (its journal) before the file is read."""
    conn = sqlite3.connect(path)
    try:
        conn.execute('SELECT count(*) FROM messages').fetchone()
    finally:
        conn.close()


@dataclass
class ReindexResult:
    """What :func:`reindex` found: the storage, the files, per-topic counts, and what was cut."""

    path: Path
    storage: str
    files: List[FileStats]
    topics: List[Tuple[Connection, int]]
    cuts: List[str]

    def summary(self) -> str:
        total = sum(f.count for f in self.files)
        lines = [
            f'reindexed {self.path}: {len(self.files)} {self.storage} file(s), {total} '
            f'messages, topics: '
            + (', '.join(f'{c.topic} ({c.msgtype}) {n}' for c, n in self.topics) or 'none')
        ]
        return '\n'.join(lines + [f'  {cut}' for cut in self.cuts])


def _file_index(path: Path) -> Tuple[FileStats, List[Connection]]:
    """Statistics and connections (with counts) of one storage file."""
    with as_bag_error(path, 'read storage file'):
        storage = storage_reader(path)
        try:
            stats = FileStats(path.name)
            if storage.metadata.message_count:
                stats.add(storage.metadata.start_time, storage.metadata.message_count)
                stats.add(storage.metadata.end_time - 1, 0)
            return stats, list(storage.connections)
        finally:
            storage.close()


def _merge(connections: List[Connection]) -> List[Tuple[Connection, int]]:
    """One entry per (topic, type), counts summed; hashes of known (Jazzy) types filled in."""
    merged: Dict[Tuple[str, str], List] = {}
    for conn in connections:
        key = (conn.topic, conn.msgtype)
        if key not in merged:
            digest = conn.digest or (
                TYPESTORE.hash_rihs01(conn.msgtype) if conn.msgtype in TYPESTORE.types else ''
            )
            merged[key] = [conn._replace(digest=digest), 0]
        merged[key][1] += conn.msgcount
    return [(conn, count) for conn, count in merged.values()]


def reindex(path) -> ReindexResult:
    """Repair cut storage files of the bag directory ``path`` and rewrite its ``metadata.yaml``.

    Raises :class:`BagError` for a path that is not a directory, holds no storage file, mixes MCAP
    and sqlite3 files, or holds a file that cannot be read at all.
    """
    path = Path(path)
    if not path.is_dir():
        raise BagError(f'cannot reindex {path}: not a directory (reindex takes a bag directory)')
    files = storage_files(path)
    if not files:
        raise BagError(f'cannot reindex {path}: it holds no .mcap or .db3 file')
    suffixes = {f.suffix for f in files}
    if len(suffixes) > 1:
        raise BagError(f'cannot reindex {path}: it mixes .mcap and .db3 files')
    storage = 'mcap' if suffixes == {'.mcap'} else 'sqlite3'
    cuts = []
    for file in files:
        with as_bag_error(file, 'repair storage file'):
            if storage == 'mcap':
                cuts.append(repair_mcap(file))
            else:
                recover_sqlite3(file)
    indexed = [_file_index(f) for f in files]
    topics = _merge([c for _, conns in indexed for c in conns])
    stats = [s for s, _ in indexed]
    try:
        write_metadata(path, bag_metadata(storage, stats, topics))
    except OSError as err:
        raise BagError(f'cannot write {path / "metadata.yaml"}: {err}') from None
    return ReindexResult(path, storage, stats, topics, [c for c in cuts if c])


# ---- vib-estimator reindex BAG (prints what it found and what was cut; a directory it cannot
# reindex gives one error: line and exit code 2) ----------------------------------------------
def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('bag', help='rosbag2 directory of .mcap or .db3 files')


def run(args: argparse.Namespace) -> int:
    try:
        result = reindex(args.bag)
    except BagError as err:
        return report(err)
    print(result.summary())
    return 0
