# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Reading and writing rosbag2 bags (MCAP or sqlite3 storage) without ROS: built on ``rosbags``.

No rclpy import, so that the offline ``vib-estimator analyze`` command, ``scripts/make_bags.py``
and the tests work without a ROS graph. Three things live here:

* :func:`read_wrench_series` -- the header stamps and one field of a
  ``geometry_msgs/WrenchStamped`` topic, as numpy arrays, in recorded order (what ``analyze`` feeds
  the estimator);
* :class:`BagReader` -- the topics of a bag (type, count, offered QoS) and its messages as raw CDR
  bytes in log-time order (what the bag replayer publishes);
* :class:`BagWriter` -- a rosbag2 directory (``metadata.yaml`` + one ``.mcap`` or ``.db3`` file)
  with message definitions embedded and the offered QoS profiles recorded per topic (what the
  recorder and ``make_bags.py`` write).

Every problem with a bag -- missing path, not a bag, corrupt or truncated file, no messages,
unknown topic, wrong or unknown message type -- is raised as
:class:`~vib_estimator.errors.BagError` with one sentence that names the path (and the topics
available, where that helps).

Damaged records. MCAP storage files are read by :mod:`.mcap`, which checks each chunk (its CRC-32,
which :class:`BagWriter` writes, and its size) and each message index entry; every message is also
decoded as its type (CDR). A damaged record is skipped and counted (``BagReader.corrupt``, the
first described in ``BagReader.damage``); with ``strict`` it raises
:class:`~vib_estimator.errors.CorruptRecordError`.

Metadata version. :class:`BagWriter` writes rosbag2 metadata version 8. That version stores
``type_description_hash`` and ``ros_distro`` and keeps ``offered_qos_profiles`` as a YAML string
with integer enums. rosbag2 readers decode every version up to their own, so a version-8 bag
reads in Jazzy whichever of 8 or 9 Jazzy writes. A version-9 bag (QoS as a YAML list with string
enums) would fail in a reader older than that change. The MCAP file follows the ``ros2`` MCAP
profile: ``ros2msg`` schemas with the full message definitions, ``cdr`` channels whose
``offered_qos_profiles`` user data is that same YAML string, and the ``rosbag2`` metadata record.
"""

from __future__ import annotations

import contextlib
import heapq
import os
import sqlite3
import zlib
from dataclasses import dataclass
from functools import partial
from operator import itemgetter
from pathlib import Path
from typing import Dict, Iterator, List, Optional, Sequence, Tuple

import numpy as np
import yaml
from rosbags.interfaces import (
    Connection,
    ConnectionExtRosbag2,
    MessageDefinition,
    MessageDefinitionFormat,
    Nodetype,
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2 import CompressionMode, Reader
from rosbags.rosbag2.metadata import dump_qos_v8
from rosbags.rosbag2.storage_mcap import DECOMPRESSORS, McapReader, McapWriter
from rosbags.rosbag2.storage_sqlite3 import Sqlite3Reader, Sqlite3Writer
from rosbags.typesys import Stores, get_typestore

from ..errors import BagError, DamageCount, McapFormatError, as_bag_error
from . import cdr, mcap
from .csv_reader import CSV_SUFFIXES
from .fields import (
    JOINT_STATE,
    WRENCH_STAMPED,
    XYZ,
    check_component,
    component_getter,
    component_setter,
    normalise_type,
    stamp_ns,
)

#: message types of the ROS 2 Jazzy distribution (serialisation, message definitions, hashes)
TYPESTORE = get_typestore(Stores.ROS2_JAZZY)

#: rosbag2 metadata version written by :class:`BagWriter` (see the module docstring)
METADATA_VERSION = 8

#: ``storage`` argument of :class:`BagWriter` -> file extension
STORAGES = {'mcap': '.mcap', 'sqlite3': '.db3'}
#: storage-file extension -> rosbags reader of one such file
_STORAGE_READERS = {'.mcap': McapReader, '.db3': Sqlite3Reader}

_INFINITE = QosTime(9223372036, 854775807)  # RMW_DURATION_INFINITE, as rosbag2 records it

#: offered QoS recorded for topics written without one: what ``ros2 bag record`` stores for a
#: reliable, volatile publisher (history and depth are not visible on the graph, hence UNKNOWN / 0)
RELIABLE_VOLATILE = Qos(
    QosHistory.UNKNOWN,
    0,
    QosReliability.RELIABLE,
    QosDurability.VOLATILE,
    _INFINITE,
    _INFINITE,
    QosLiveliness.AUTOMATIC,
    _INFINITE,
    False,
)


def _bag_time(duration) -> QosTime:
    return QosTime(*divmod(duration.nanoseconds, 1_000_000_000))


def bag_qos(profile) -> Qos:
    """An offered QoS profile (an ``rclpy.qos.QoSProfile``: its policies as ints, durations with
    ``nanoseconds``) as rosbag2 records it in the bag's metadata."""

    def enum(cls, policy):
        return cls(int(policy)) if int(policy) in {e.value for e in cls} else cls.UNKNOWN

    return Qos(
        enum(QosHistory, profile.history),
        profile.depth,
        enum(QosReliability, profile.reliability),
        enum(QosDurability, profile.durability),
        _bag_time(profile.deadline),
        _bag_time(profile.lifespan),
        enum(QosLiveliness, profile.liveliness),
        _bag_time(profile.liveliness_lease_duration),
        profile.avoid_ros_namespace_conventions,
    )


@dataclass(frozen=True)
class WrenchSeries:
    """One field of a WrenchStamped topic.

    Attributes:
        stamps_ns: header stamps, integer ns (exact), in recorded order.
        values: the chosen field (e.g. ``torque.z``) of each message.
        frame_id: header frame of the first message.
        topic: the topic read.
    """

    stamps_ns: np.ndarray
    values: np.ndarray
    frame_id: str
    topic: str

    def __len__(self) -> int:
        return len(self.stamps_ns)


@dataclass(frozen=True)
class TopicInfo:
    """A topic of a bag: name, type (``pkg/msg/Name``), message count and offered QoS profiles."""

    topic: str
    msgtype: str
    count: int
    offered_qos: Tuple[Qos, ...]


@dataclass(frozen=True)
class BagMessage:
    """A recorded message: topic, type, log (receive) time in ns, and its serialized CDR bytes."""

    topic: str
    msgtype: str
    log_time_ns: int
    data: bytes


def storage_reader(path: Path):
    """The rosbags reader of one storage file (``.mcap`` or ``.db3``), opened."""
    storage = _STORAGE_READERS[path.suffix](path)
    storage.open()
    return storage


class BagReader(DamageCount):
    """An open bag: an MCAP file, an sqlite3 ``.db3`` file, or a rosbag2 directory of either.

    Use as a context manager. Raises :class:`BagError` if the path is missing or not a readable
    bag, or holds no messages.

    Everything but the list of storage files (and their compression) comes from the storage files
    themselves, not from ``metadata.yaml``: topics, types, counts, offered QoS and the log-time
    span. rosbag2 has written wrong values there (split bags whose ``starting_time`` and
    ``duration`` are those of the last file, ros2/rosbag2#841 and #966), and rosbags' directory
    reader, which trusts them, also drops every message of a topic whose QoS in ``metadata.yaml``
    differs from the one in the storage file (it matches connections on the whole QoS list) -- the
    case of rosbag2's own ``talker`` bags. Messages of split bags are merged across files in log
    time. Types written ``pkg/Name`` (older bags) are reported as ``pkg/msg/Name``.

    Damaged records (see the module docstring) are skipped: :attr:`corrupt` counts them,
    :attr:`damage` describes the first; ``strict`` makes the first one raise
    :class:`~vib_estimator.errors.CorruptRecordError`.
    """

    def __init__(self, path, strict: bool = False) -> None:
        self.path = Path(path)
        self.strict = strict
        #: damaged records skipped so far (chunks' messages, index entries, payloads)
        self.corrupt = 0
        #: the first damage, described ('' if none)
        self.damage = ''
        check_bag_path(self.path)
        self._stack = contextlib.ExitStack()
        self._decompress = None
        with as_bag_error(self.path, 'open bag'):
            try:
                self._storages = self._open_storages()
            except BaseException:
                self._stack.close()
                raise
        self.topics: Dict[str, TopicInfo] = _merge_topics(self._storages)
        stats = [s.metadata for s in self._storages if s.metadata.message_count]
        self.message_count = sum(m.message_count for m in stats)
        if self.message_count == 0:
            self.close()
            raise BagError(f'bag {self.path} contains no messages')
        #: log time of the first message, ns
        self.start_ns = min(m.start_time for m in stats)
        #: log time of the last message, ns (rosbags reports one past it)
        self.end_ns = max(m.end_time for m in stats) - 1

    def _open_storages(self) -> list:
        if self.path.is_file():
            storage = storage_reader(self.path)
            self._stack.callback(storage.close)
            return [storage]
        reader = Reader(self.path)  # metadata.yaml: file list, decompression of the files
        reader.open()
        self._stack.callback(reader.close)
        if reader.compression_mode == 'message':  # zstd, the only one rosbag2 writes
            self._decompress = partial(DECOMPRESSORS['zstd'], _=0)
        return list(reader.storage.storages)

    def describe_topics(self) -> str:
        """``'/a (pkg/msg/A), /b (pkg/msg/B)'`` for error messages."""
        return ', '.join(f'{t.topic} ({t.msgtype})' for t in self.topics.values()) or 'none'

    def topic(self, name: str) -> TopicInfo:
        """The :class:`TopicInfo` of ``name``, or :class:`BagError` listing the bag's topics."""
        if name not in self.topics:
            raise BagError(
                f'bag {self.path} has no topic {name!r}; its topics are {self.describe_topics()}'
            )
        return self.topics[name]

    def _stream(self, storage, names: set, start_ns: Optional[int]):
        """``(topic, log time, data)`` of one storage file: MCAP by :mod:`.mcap` (checked), else
        (sqlite3, unindexed MCAP, compressed messages) by rosbags."""
        path = Path(storage.path)
        if path.suffix == '.mcap' and self._decompress is None:
            try:
                return mcap.iter_messages(path, names, start_ns, self.count_damage)
            except (McapFormatError, OSError):
                pass
        conns = [c for c in storage.connections if c.topic in names]
        return ((c.topic, t, d) for c, t, d in storage.messages(conns, start_ns, None))

    def messages(
        self,
        topics: Optional[Sequence[str]] = None,
        start_ns: Optional[int] = None,
        check: bool = True,
    ) -> Iterator[BagMessage]:
        """The messages of ``topics`` (default: all), from log time ``start_ns`` on, in log-time
        order across all storage files (ties: in file order). ``check``: decode each payload as
        its type (a Jazzy type) and skip those that do not decode, as damaged records."""
        names = set(self.topics) if topics is None else {self.topic(t).topic for t in topics}
        found, before, undecodable = 0, self.corrupt, 0
        with as_bag_error(self.path, 'read messages of bag'):
            streams = [
                self._stream(s, names, start_ns)
                for s in self._storages
                if any(c.topic in names for c in s.connections)
            ]
            for topic, log_time, data in heapq.merge(*streams, key=itemgetter(1)):
                found += 1
                if self._decompress is not None:
                    data = self._decompress(data)
                msgtype = self.topics[topic].msgtype
                if check and not _decodes(data, msgtype):
                    undecodable += 1
                    self.count_damage(
                        1,
                        f'a {topic} message logged at {log_time} ns does not decode as {msgtype}',
                    )
                    continue
                yield BagMessage(topic, msgtype, log_time, bytes(data))
        if start_ns is None:  # the whole bag: what its statistics count but no read found
            skipped_unread = self.corrupt - before - undecodable  # damaged chunks, entries
            missing = sum(self.topics[t].count for t in names) - found - skipped_unread
            self.count_damage(
                max(missing, 0), f'{missing} messages counted by the bag were not found in it'
            )

    def close(self) -> None:
        self._stack.close()

    def __enter__(self) -> 'BagReader':
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _decodes(data: bytes, msgtype: str) -> bool:
    """Whether ``data`` deserialises as ``msgtype`` (True for a type rosbags does not know);
    fixed-layout types by :func:`.cdr.fits_layout` (the same answer, ~10x faster)."""
    if cdr.is_fixed_layout(msgtype):
        return cdr.fits_layout(data, msgtype)
    if msgtype not in TYPESTORE.types:
        return True
    try:
        TYPESTORE.deserialize_cdr(data, msgtype)
        return True
    except Exception:  # noqa: BLE001 -- rosbags raises what its parsing step does
        return False


def only_topic(path: Path, candidates: List[str], what: str, listing: str, how: str = '') -> str:
    """The one topic of ``candidates`` (shown as they are given), else BagError: none (with the
    bag's ``listing``) or several (choose one, ``how``)."""
    if not candidates:
        raise BagError(f'bag {path} has no {what} topic; its topics are {listing}')
    if len(candidates) > 1:
        raise BagError(
            f'bag {path} has several {what} topics, choose one{how}: {", ".join(candidates)}'
        )
    return candidates[0].split(' ')[0]


#: what to do with a file of a kind users bring that is neither a bag nor a CSV file
NOT_A_BAG = {
    '.npy': (
        "; a NumPy array: write it as one, e.g. a = numpy.load(path); numpy.savetxt('rec.csv', "
        "a.T if a.shape[0] < a.shape[1] else a, delimiter=',') (time first)"
    ),
    '.npz': '; NumPy arrays: write the time and the signals as the columns of a CSV file',
    '.mat': '; a MATLAB file: writematrix([t y], "rec.csv") writes it as one',
    '.xlsx': '; a spreadsheet: save it as CSV',
    '.xls': '; a spreadsheet: save it as CSV',
}


def check_bag_path(path: Path) -> None:
    """:class:`BagError` unless ``path`` is a ``.mcap``/``.db3`` file or a directory with a
    ``metadata.yaml`` (a directory of storage files without one: run ``vib-estimator reindex``)."""
    if not path.exists():
        raise BagError(f'bag {path} does not exist')
    if path.is_dir() and not (path / 'metadata.yaml').exists():
        if storage_files(path):
            raise BagError(
                f'bag {path} has no metadata.yaml: run `vib-estimator reindex {path}` '
                f'to rebuild it from its storage files'
            )
        raise BagError(
            f'{path} is not a rosbag2 bag: it has no metadata.yaml and no .mcap or .db3 file'
        )
    if path.is_file() and path.suffix not in _STORAGE_READERS:
        hint = NOT_A_BAG.get(path.suffix.lower(), '')
        raise BagError(
            f'{path} is not a bag: expected a .mcap or .db3 file or a rosbag2 directory, or a '
            f'CSV file ({", ".join(CSV_SUFFIXES)}: the time first){hint}'
        )


def storage_files(directory: Path) -> List[Path]:
    """The ``.mcap`` / ``.db3`` files of a bag directory, in split order (``name_0``, ``name_1``,
    ..., ``name_10``: by the number after the last ``_``, then by name)."""

    def order(path: Path):
        stem, _, index = path.stem.rpartition('_')
        return (stem, int(index)) if index.isdigit() else (path.stem, -1)

    return sorted(
        (p for p in directory.iterdir() if p.is_file() and p.suffix in _STORAGE_READERS), key=order
    )


def _merge_topics(storages) -> Dict[str, TopicInfo]:
    """The topics of all storage files: counts summed, type and QoS of the first file with it."""
    counts: Dict[str, int] = {}
    first = {}
    for storage in storages:
        for conn in storage.connections:
            counts[conn.topic] = counts.get(conn.topic, 0) + conn.msgcount
            first.setdefault(conn.topic, conn)
    return {
        topic: TopicInfo(
            topic,
            normalise_type(conn.msgtype),
            counts[topic],
            tuple(
                conn.ext.offered_qos_profiles if isinstance(conn.ext, ConnectionExtRosbag2) else ()
            ),
        )
        for topic, conn in first.items()
    }


def read_wrench_series(
    path, topic: Optional[str] = None, component: str = 'torque.z'
) -> WrenchSeries:
    """Header stamps and ``component`` of a WrenchStamped topic of a bag, in recorded order.

    ``topic=None`` takes the bag's only WrenchStamped topic. Raises :class:`BagError` for a bag
    that cannot be read, an unknown topic, a topic of another type, or no (or several)
    WrenchStamped topics when ``topic`` is None; ``ValueError`` for an unknown ``component``.
    """
    value_of = component_getter(component)
    with BagReader(path) as bag:
        if topic is None:
            topic = only_topic(
                bag.path,
                [t.topic for t in bag.topics.values() if t.msgtype == WRENCH_STAMPED],
                WRENCH_STAMPED,
                bag.describe_topics(),
            )
        info = bag.topic(topic)
        if info.msgtype != WRENCH_STAMPED:
            raise BagError(
                f'topic {topic} of bag {bag.path} has type {info.msgtype}, not {WRENCH_STAMPED}'
            )
        stamps: List[int] = []
        values: List[float] = []
        frame_id = ''
        with as_bag_error(bag.path, f'decode {topic} in'):
            for message in bag.messages([topic], check=False):
                try:
                    msg = TYPESTORE.deserialize_cdr(message.data, WRENCH_STAMPED)
                except Exception:  # noqa: BLE001 -- as in BagReader.messages
                    bag.count_damage(
                        1,
                        f'a {topic} message logged at {message.log_time_ns} ns '
                        f'does not decode as {WRENCH_STAMPED}',
                    )
                    continue
                if not stamps:
                    frame_id = msg.header.frame_id
                stamps.append(stamp_ns(msg.header))
                values.append(value_of(msg))
    return WrenchSeries(
        np.array(stamps, dtype=np.int64), np.array(values, dtype=np.float64), frame_id, topic
    )


def wrench_message(stamp: int, frame_id: str, component: str, value: float):
    """A rosbags WrenchStamped: header ``stamp`` (ns), ``frame_id``; ``component`` = ``value``."""
    types = TYPESTORE.types
    vec = {'force': [0.0, 0.0, 0.0], 'torque': [0.0, 0.0, 0.0]}
    part, axis = check_component(component).split('.')
    vec[part][XYZ.index(axis)] = float(value)
    header = types['std_msgs/msg/Header'](
        stamp=types['builtin_interfaces/msg/Time'](
            sec=stamp // 1_000_000_000, nanosec=stamp % 1_000_000_000
        ),
        frame_id=frame_id,
    )
    vector = types['geometry_msgs/msg/Vector3']
    return types[WRENCH_STAMPED](
        header=header,
        wrench=types['geometry_msgs/msg/Wrench'](
            force=vector(*vec['force']), torque=vector(*vec['torque'])
        ),
    )


def zero_message(msgtype: str):
    """A rosbags message of ``msgtype`` (a Jazzy type whose arrays and sequences hold base
    values, as every input type's) with every field zero, empty or ``False``."""
    args = {}
    for name, (kind, detail) in TYPESTORE.fielddefs[msgtype][1]:
        if kind == Nodetype.NAME:
            args[name] = zero_message(detail)
        elif kind == Nodetype.BASE:
            args[name] = _ZERO_BASE.get(detail[0], 0)
        else:  # an array (fixed size) or a sequence of base values
            (_, (base, _)), size = detail
            args[name] = [] if base == 'string' else np.zeros(size, _NUMPY_BASE.get(base, base))
    return TYPESTORE.types[msgtype](**args)


def channels_message(msgtype: str, stamp: int, frame_id: str, channels: Sequence[str], values):
    """A rosbags message of an input type with header ``stamp`` (ns) and ``frame_id`` whose
    ``channels`` (components, :mod:`.fields`) hold ``values``, everything else zero."""
    msg = zero_message(msgtype)
    if hasattr(msg, 'header'):
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(stamp), 1_000_000_000)
        msg.header.frame_id = frame_id
    for channel, value in zip(channels, values):
        component_setter(channel, msgtype)(msg, value)
    if msgtype == JOINT_STATE:  # the setter's lists as the arrays the serialiser takes
        for name in ('position', 'velocity', 'effort'):
            setattr(msg, name, np.asarray(getattr(msg, name), dtype=np.float64))
    return msg


def write_channels(
    path, topic: str, msgtype: str, channels: Sequence[str], stamps, values, frame_id: str = ''
) -> None:
    """A one-topic bag of ``msgtype`` messages, the columns of ``values`` (samples x channels)
    in ``channels``, header stamps ``stamps`` (ns; log time the same: a clean recording)."""
    with BagWriter(path) as bag:
        conn = bag.add_topic(topic, msgtype)
        for stamp, row in zip(np.asarray(stamps).tolist(), np.asarray(values).tolist()):
            bag.write_message(
                conn, stamp, channels_message(msgtype, stamp, frame_id, channels, row)
            )


#: zero values of the base types that are not integers, and numpy names of the others'
_ZERO_BASE = {'string': '', 'bool': False, 'float32': 0.0, 'float64': 0.0}
_NUMPY_BASE = {'octet': 'uint8', 'char': 'uint8', 'byte': 'uint8'}


_NO_MESSAGE = 2**63 - 1  # start time of a file without messages, as rosbags keeps it


@dataclass
class FileStats:
    """One storage file of a bag as ``metadata.yaml`` lists it: name, log-time span, count."""

    name: str
    start_ns: int = _NO_MESSAGE
    end_ns: int = 0
    count: int = 0

    def add(self, log_time_ns: int, n: int = 1) -> None:
        self.start_ns = min(self.start_ns, log_time_ns)
        self.end_ns = max(self.end_ns, log_time_ns)
        self.count += n

    def as_dict(self) -> dict:
        return {
            'path': self.name,
            'starting_time': {'nanoseconds_since_epoch': self.start_ns},
            'duration': {'nanoseconds': max(0, self.end_ns - self.start_ns)},
            'message_count': self.count,
        }


def bag_metadata(
    storage: str, files: Sequence[FileStats], topics: Sequence[Tuple[Connection, int]]
) -> dict:
    """The ``rosbag2_bagfile_information`` of a bag (version :data:`METADATA_VERSION`), from its
    files and its ``(connection, message count)`` topics; what :class:`BagWriter` and
    ``vib-estimator reindex`` write."""
    whole = FileStats('')
    for stats in files:
        if stats.count:
            whole.add(stats.start_ns, stats.count)
            whole.add(stats.end_ns, 0)
    info = whole.as_dict()
    return {
        'version': METADATA_VERSION,
        'storage_identifier': storage,
        'relative_file_paths': [f.name for f in files],
        'duration': info['duration'],
        'starting_time': info['starting_time'],
        'message_count': whole.count,
        'topics_with_message_count': [
            {
                'topic_metadata': {
                    'name': c.topic,
                    'type': c.msgtype,
                    'serialization_format': c.ext.serialization_format,
                    'offered_qos_profiles': dump_qos_v8(c.ext.offered_qos_profiles),
                    'type_description_hash': c.digest,
                },
                'message_count': count,
            }
            for c, count in topics
        ],
        'compression_format': '',
        'compression_mode': '',
        'files': [f.as_dict() for f in files],
        'custom_data': None,
        'ros_distro': 'rosbags',
    }


def _yaml_text(data) -> str:
    return yaml.safe_dump(data, default_flow_style=False, width=100)


def write_metadata(directory: Path, info: dict) -> None:
    """Write ``directory/metadata.yaml`` atomically (a crash leaves the old or the new one)."""
    tmp = directory / 'metadata.yaml.tmp'
    tmp.write_text(_yaml_text({'rosbag2_bagfile_information': info}), 'utf8')
    tmp.replace(directory / 'metadata.yaml')


#: bytes of records per MCAP chunk written (rosbags: 1 MiB). A damaged chunk loses all its
#: messages, so smaller chunks lose less: 64 KiB is ~600 WrenchStamped messages, for an index of
#: 0.4 %
CHUNK_BYTES = 1 << 16


class _ChecksummedMcap(McapWriter):
    """rosbags' MCAP writer, with each chunk's CRC-32 (of its uncompressed records) set, so that
    readers (:mod:`.mcap`, the ``mcap`` tools, rosbag2) detect a damaged chunk, and chunks of
    :data:`CHUNK_BYTES`."""

    def write(self, connection: Connection, timestamp: int, data: bytes) -> None:
        super().write(connection, timestamp, data)
        if self.chunk.bio.tell() > CHUNK_BYTES:
            self.close_chunk()

    def close_chunk(self) -> None:
        crc = zlib.crc32(self.chunk.bio.getvalue())
        start = self.bio.tell()
        super().close_chunk()
        end = self.bio.tell()
        self.bio.seek(start + mcap.CHUNK_CRC_AT)
        self.bio.write(crc.to_bytes(4, 'little'))
        self.bio.seek(end)


def mcap_file(path: Path) -> McapWriter:
    """rosbags' MCAP storage writer (chunk CRCs set), writing the new file ``path``.

    That writer names its file after the directory it is given, so it is given a scratch directory
    and its open file is then moved to ``path`` (an open file keeps its data when renamed).
    """
    scratch = path.with_name(path.name + '.tmpdir')
    scratch.mkdir()
    writer = _ChecksummedMcap(scratch, CompressionMode.NONE)
    writer.path = writer.path.rename(path)
    scratch.rmdir()
    return writer


class _Sqlite3File(Sqlite3Writer):
    """rosbags' sqlite3 storage writer, for a file name of our choosing (``name_3.db3``)."""

    def __init__(self, path: Path) -> None:  # noqa: D107 -- the parent's, with the path given
        self.path = path
        self.conn = sqlite3.connect(f'file:{path}?mode=rwc', uri=True)
        self.conn.executescript(self.SQLITE_SCHEMA)
        self.cursor = self.conn.cursor()


def connection_for(topic: str, msgtype: str, offered_qos: Sequence[Qos], cid: int) -> Connection:
    """A rosbags connection of a Jazzy type, with its message definition and RIHS01 hash."""
    msgdef, _ = TYPESTORE.generate_msgdef(msgtype, ros_version=2)
    return Connection(
        cid,
        topic,
        msgtype,
        MessageDefinition(MessageDefinitionFormat.MSG, msgdef),
        TYPESTORE.hash_rihs01(msgtype),
        0,
        ConnectionExtRosbag2('cdr', list(offered_qos)),
        None,
    )


class BagWriter:
    """Writes a new rosbag2 directory (``metadata.yaml`` + storage files); a context manager.

    ``storage`` is ``'mcap'`` (the Jazzy default) or ``'sqlite3'``. The directory must not exist.
    Without splitting the bag has one file, ``<name>.mcap`` (or ``.db3``); with ``max_bag_size``
    (bytes) or ``max_bag_duration_ns`` (log time) > 0 it is split like rosbag2 into
    ``<name>_0.mcap``, ``<name>_1.mcap``, ...: a new file is begun before a message that would
    go into a file already that large or that long.

    Crash safety: ``metadata.yaml`` is written when the bag is opened and rewritten each time a
    file is opened or closed. :meth:`flush` puts every message written so far into the storage
    file (MCAP: closes the pending chunk, flushes and fsyncs; sqlite3: commits), so a process
    killed afterwards loses nothing written before; ``vib-estimator reindex`` then rebuilds the
    index and ``metadata.yaml`` from what is complete. Any failure to write (disk full, file too
    large, I/O error) is raised as :class:`BagError`; what was flushed before stays readable.
    """

    def __init__(
        self, path, storage: str = 'mcap', max_bag_size: int = 0, max_bag_duration_ns: int = 0
    ) -> None:
        self.path = Path(path)
        if storage not in STORAGES:
            raise ValueError(f'storage must be one of {", ".join(STORAGES)}, got {storage!r}')
        if self.path.exists():
            raise BagError(f'{self.path} exists already; a bag is written to a new directory')
        self.storage = storage
        self._limits = (max_bag_size, max_bag_duration_ns)
        self._connections: List[Connection] = []
        self._counts: Dict[int, int] = {}
        self.files: List[FileStats] = []
        self._file = None  # the storage writer of the file being written
        self._types: set = set()  # message types whose definition is in the current file
        self._failed = False

    @contextlib.contextmanager
    def _writing(self):
        """Any failure of the storage as one :class:`BagError` (the writer stops writing)."""
        try:
            yield
        except (OSError, sqlite3.Error) as err:
            self._failed = True
            raise BagError(
                f'cannot write bag {self.path}: {err}; what was written before is '
                f'kept (`vib-estimator reindex {self.path}` makes it readable)'
            ) from None

    def open(self) -> 'BagWriter':
        try:
            self.path.mkdir(parents=True)
        except OSError as err:
            raise BagError(
                f'cannot create bag directory {self.path}: {err.strerror or err}'
            ) from None
        with self._writing():
            self._open_file()
        return self

    def _file_name(self, index: int) -> str:
        ext = STORAGES[self.storage]
        return f'{self.path.name}_{index}{ext}' if any(self._limits) else self.path.name + ext

    def _open_file(self) -> None:
        name = self._file_name(len(self.files))
        if self.storage == 'mcap':
            self._file = mcap_file(self.path / name)
        else:
            self._file = _Sqlite3File(self.path / name)
        self._types = set()
        self._uncommitted = 0  # bytes of messages written to the file since the last flush
        self.files.append(FileStats(name))
        for connection in self._connections:
            self._register(connection)
        self._write_metadata()

    def _register(self, connection: Connection) -> None:
        if connection.msgtype not in self._types:
            self._file.add_msgtype(connection)
            self._types.add(connection.msgtype)
        self._file.add_connection(connection, dump_qos_v8(connection.ext.offered_qos_profiles))

    def _metadata(self) -> dict:
        return bag_metadata(
            self.storage, self.files, [(c, self._counts[c.id]) for c in self._connections]
        )

    def _write_metadata(self) -> None:
        write_metadata(self.path, self._metadata())

    def add_topic(
        self, topic: str, msgtype: str, offered_qos: Sequence[Qos] = (RELIABLE_VOLATILE,)
    ) -> Connection:
        """Register ``topic`` of ``msgtype`` (a Jazzy type); return the handle to write it with."""
        if msgtype not in TYPESTORE.types:
            raise BagError(
                f'cannot record {topic}: message type {msgtype} is not a ROS 2 Jazzy type'
            )
        connection = connection_for(topic, msgtype, offered_qos, len(self._connections) + 1)
        with self._writing():
            self._register(connection)
        self._connections.append(connection)
        self._counts[connection.id] = 0
        return connection

    def _file_full(self, log_time_ns: int) -> bool:
        max_size, max_duration = self._limits
        current = self.files[-1]
        if max_duration and current.count and log_time_ns - current.start_ns >= max_duration:
            return True
        if not max_size or not current.count:
            return False
        if self.storage == 'mcap':
            size = self._file.bio.tell() + self._file.chunk.bio.tell()
        else:  # the file grows at each commit: add what was written since
            size = self._file.path.stat().st_size + self._uncommitted
        return size >= max_size

    def write(self, connection: Connection, log_time_ns: int, data: bytes) -> None:
        """Append serialized (CDR) ``data`` received at ``log_time_ns``."""
        if self._failed:
            raise BagError(f'bag {self.path} stopped writing after an error')
        with self._writing():
            if any(self._limits) and self._file_full(log_time_ns):
                self._close_file()
                self._open_file()
            self._file.write(connection, log_time_ns, data)
        self._uncommitted += len(data)
        self._counts[connection.id] += 1
        self.files[-1].add(log_time_ns)

    def write_message(self, connection: Connection, log_time_ns: int, msg) -> None:
        """Serialize the rosbags message ``msg`` and append it."""
        self.write(connection, log_time_ns, TYPESTORE.serialize_cdr(msg, connection.msgtype))

    def flush(self) -> None:
        """Put every message written so far into the storage file (see the class docstring)."""
        if self._file is None or self._failed:
            return
        with self._writing():
            if self.storage == 'mcap':
                if self._file.chunk.bio.tell():
                    self._file.close_chunk()
                self._file.bio.flush()
                os.fsync(self._file.bio.fileno())
            else:
                self._file.conn.commit()
            self._uncommitted = 0

    def _close_file(self) -> None:
        self._file.close(METADATA_VERSION, _yaml_text(self._metadata()).strip())
        self._file = None
        self._write_metadata()

    def close(self) -> None:
        """Finish the bag (index, statistics, ``metadata.yaml``); idempotent. After a write
        error only the file handles are released (the bag then needs ``reindex``)."""
        if self._file is None:
            return
        if self._failed:
            self.abort()
            return
        with self._writing():
            self._close_file()

    def abort(self) -> None:
        """Release the storage file without finishing it (what was flushed stays)."""
        storage, self._file = self._file, None
        if storage is not None:
            with contextlib.suppress(Exception):
                storage.abort() if self.storage == 'sqlite3' else storage.bio.close()

    def __enter__(self) -> 'BagWriter':
        return self.open()

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()


def write_wrench_series(
    path, series: WrenchSeries, component: str = 'torque.z', storage: str = 'mcap'
) -> None:
    """Write ``series`` as a one-topic bag, log time = header stamp (a clean recording)."""
    with BagWriter(path, storage) as bag:
        conn = bag.add_topic(series.topic, WRENCH_STAMPED)
        for stamp, value in zip(series.stamps_ns.tolist(), series.values.tolist()):
            bag.write_message(
                conn, stamp, wrench_message(stamp, series.frame_id, component, value)
            )
