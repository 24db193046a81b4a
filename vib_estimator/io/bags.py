"""Reading and writing rosbag2 bags (MCAP or sqlite3 storage) without ROS: built on ``rosbags``.

No rclpy import, so that the offline ``vib-estimator analyze`` command, ``scripts/make_bags.py``
and the tests work without a ROS graph. Three things live here:

* :func:`read_wrench_series` -- the header stamps and one field of a ``geometry_msgs/WrenchStamped``
  topic, as numpy arrays, in recorded order (what ``analyze`` feeds the estimator);
* :class:`BagReader` -- the topics of a bag (type, count, offered QoS) and its messages as raw CDR
  bytes in log-time order (what the bag replayer publishes);
* :class:`BagWriter` -- a rosbag2 directory (``metadata.yaml`` + one ``.mcap`` or ``.db3`` file)
  with message definitions embedded and the offered QoS profiles recorded per topic (what the
  recorder and ``make_bags.py`` write).

Every problem with a bag -- missing path, not a bag, corrupt or truncated file, no messages, unknown
topic, wrong or unknown message type -- is raised as :class:`BagError` with one sentence that names
the path (and the topics available, where that helps).

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
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, Iterator, List, Optional, Sequence, Tuple

import numpy as np
from rosbags.interfaces import (Connection, ConnectionExtRosbag2, Qos, QosDurability, QosHistory,
                                QosLiveliness, QosReliability, QosTime)
from rosbags.rosbag2 import Reader, StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from .fields import check_component, component_getter, stamp_ns

WRENCH_STAMPED = 'geometry_msgs/msg/WrenchStamped'

#: message types of the ROS 2 Jazzy distribution (serialisation, message definitions, hashes)
TYPESTORE = get_typestore(Stores.ROS2_JAZZY)

#: rosbag2 metadata version written by :class:`BagWriter` (see the module docstring)
METADATA_VERSION = 8

#: ``storage`` argument of :class:`BagWriter` -> rosbags storage plugin
STORAGES = {'mcap': StoragePlugin.MCAP, 'sqlite3': StoragePlugin.SQLITE3}

_INFINITE = QosTime(9223372036, 854775807)  # RMW_DURATION_INFINITE, as rosbag2 records it

#: offered QoS recorded for topics written without one: what ``ros2 bag record`` stores for a
#: reliable, volatile publisher (history and depth are not visible on the graph, hence UNKNOWN / 0)
RELIABLE_VOLATILE = Qos(QosHistory.UNKNOWN, 0, QosReliability.RELIABLE, QosDurability.VOLATILE,
                        _INFINITE, _INFINITE, QosLiveliness.AUTOMATIC, _INFINITE, False)


class BagError(Exception):
    """A bag that cannot be read as asked; the message is one sentence naming the path."""


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


@contextlib.contextmanager
def _as_bag_error(path: Path, doing: str):
    """Turn any failure of the bag parser into one :class:`BagError` sentence.

    A corrupt or truncated file makes ``rosbags`` fail with whatever its parsing step raises
    (``ReaderError``, ``struct.error``, ``KeyError``, ``sqlite3.DatabaseError``, ...), so every
    exception is caught here, once, and reported with the path.
    """
    try:
        yield
    except BagError:
        raise
    except Exception as err:  # noqa: BLE001 -- see docstring
        detail = str(err).strip().rstrip('.') or type(err).__name__
        raise BagError(f'cannot {doing} {path}: {detail} (corrupt or truncated bag?)') from None


class BagReader:
    """An open bag: an MCAP file, an sqlite3 ``.db3`` file, or a rosbag2 directory of either.

    Use as a context manager. Raises :class:`BagError` if the path is missing or not a readable bag,
    or holds no messages.
    """

    def __init__(self, path) -> None:
        self.path = Path(path)
        if not self.path.exists():
            raise BagError(f'bag {self.path} does not exist')
        if self.path.is_dir() and not (self.path / 'metadata.yaml').exists():
            raise BagError(f'{self.path} is not a rosbag2 bag: it has no metadata.yaml')
        if self.path.is_file() and self.path.suffix not in ('.mcap', '.db3'):
            raise BagError(f'{self.path} is not a bag: expected a .mcap or .db3 file or a rosbag2 '
                           f'directory')
        with _as_bag_error(self.path, 'open bag'):
            self._reader = Reader(self.path)
            self._reader.open()
        self._connections = list(self._reader.connections)
        counts: Dict[str, int] = {}
        for conn in self._connections:
            counts[conn.topic] = counts.get(conn.topic, 0) + conn.msgcount
        self.topics: Dict[str, TopicInfo] = {}
        for conn in self._connections:
            qos = (conn.ext.offered_qos_profiles if isinstance(conn.ext, ConnectionExtRosbag2)
                   else [])
            self.topics.setdefault(conn.topic, TopicInfo(conn.topic, conn.msgtype,
                                                         counts[conn.topic], tuple(qos)))
        if self._reader.message_count == 0:
            self.close()
            raise BagError(f'bag {self.path} contains no messages')

    @property
    def start_ns(self) -> int:
        """Log time of the first message, ns."""
        return self._reader.start_time

    @property
    def end_ns(self) -> int:
        """Log time of the last message, ns."""
        return self._reader.end_time - 1  # rosbags reports one past the last message

    @property
    def message_count(self) -> int:
        return self._reader.message_count

    def describe_topics(self) -> str:
        """``'/a (pkg/msg/A), /b (pkg/msg/B)'`` for error messages."""
        return ', '.join(f'{t.topic} ({t.msgtype})' for t in self.topics.values()) or 'none'

    def topic(self, name: str) -> TopicInfo:
        """The :class:`TopicInfo` of ``name``, or :class:`BagError` listing the bag's topics."""
        if name not in self.topics:
            raise BagError(f'bag {self.path} has no topic {name!r}; its topics are '
                           f'{self.describe_topics()}')
        return self.topics[name]

    def messages(self, topics: Optional[Sequence[str]] = None,
                 start_ns: Optional[int] = None) -> Iterator[BagMessage]:
        """The messages of ``topics`` (default: all), from log time ``start_ns`` on, in log-time
        order (the order they were recorded in)."""
        names = set(self.topics) if topics is None else {self.topic(t).topic for t in topics}
        conns = [c for c in self._connections if c.topic in names]
        with _as_bag_error(self.path, 'read messages of bag'):
            for conn, log_time, data in self._reader.messages(connections=conns, start=start_ns):
                yield BagMessage(conn.topic, conn.msgtype, log_time, bytes(data))

    def close(self) -> None:
        self._reader.close()

    def __enter__(self) -> 'BagReader':
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def read_wrench_series(path, topic: Optional[str] = None,
                       component: str = 'torque.z') -> WrenchSeries:
    """Header stamps and ``component`` of a WrenchStamped topic of a bag, in recorded order.

    ``topic=None`` takes the bag's only WrenchStamped topic. Raises :class:`BagError` for a bag that
    cannot be read, an unknown topic, a topic of another type, or no (or several) WrenchStamped
    topics when ``topic`` is None; ``ValueError`` for an unknown ``component``.
    """
    value_of = component_getter(component)
    with BagReader(path) as bag:
        if topic is None:
            from .streaming import only_topic

            topic = only_topic(bag.path, [t.topic for t in bag.topics.values()
                                          if t.msgtype == WRENCH_STAMPED], WRENCH_STAMPED,
                               bag.describe_topics())
        info = bag.topic(topic)
        if info.msgtype != WRENCH_STAMPED:
            raise BagError(f'topic {topic} of bag {bag.path} has type {info.msgtype}, '
                           f'not {WRENCH_STAMPED}')
        stamps: List[int] = []
        values: List[float] = []
        frame_id = ''
        with _as_bag_error(bag.path, f'decode {topic} in'):
            for message in bag.messages([topic]):
                msg = TYPESTORE.deserialize_cdr(message.data, WRENCH_STAMPED)
                if not stamps:
                    frame_id = msg.header.frame_id
                stamps.append(stamp_ns(msg.header))
                values.append(value_of(msg))
    return WrenchSeries(np.array(stamps, dtype=np.int64), np.array(values, dtype=np.float64),
                        frame_id, topic)


def wrench_message(stamp: int, frame_id: str, component: str, value: float):
    """A rosbags WrenchStamped: header ``stamp`` (ns), ``frame_id``; ``component`` = ``value``."""
    types = TYPESTORE.types
    vec = {'force': [0.0, 0.0, 0.0], 'torque': [0.0, 0.0, 0.0]}
    part, axis = check_component(component).split('.')
    vec[part]['xyz'.index(axis)] = float(value)
    header = types['std_msgs/msg/Header'](
        stamp=types['builtin_interfaces/msg/Time'](sec=stamp // 1_000_000_000,
                                                   nanosec=stamp % 1_000_000_000),
        frame_id=frame_id)
    vector = types['geometry_msgs/msg/Vector3']
    return types[WRENCH_STAMPED](header=header, wrench=types['geometry_msgs/msg/Wrench'](
        force=vector(*vec['force']), torque=vector(*vec['torque'])))


class BagWriter:
    """Writes a new rosbag2 directory (``metadata.yaml`` + one storage file); a context manager.

    ``storage`` is ``'mcap'`` (the Jazzy default) or ``'sqlite3'``. The directory must not exist.
    On leaving the ``with`` block (or :meth:`close`) the storage file's index and ``metadata.yaml``
    are written; after an exception the partial bag is left without them.
    """

    def __init__(self, path, storage: str = 'mcap') -> None:
        self.path = Path(path)
        if storage not in STORAGES:
            raise ValueError(f'storage must be one of {", ".join(STORAGES)}, got {storage!r}')
        if self.path.exists():
            raise BagError(f'{self.path} exists already; a bag is written to a new directory')
        self._writer = Writer(self.path, version=METADATA_VERSION, storage_plugin=STORAGES[storage])
        self._open = False

    def open(self) -> 'BagWriter':
        self._writer.open()
        self._open = True
        return self

    def add_topic(self, topic: str, msgtype: str,
                  offered_qos: Sequence[Qos] = (RELIABLE_VOLATILE,)) -> Connection:
        """Register ``topic`` of ``msgtype`` (a Jazzy type); return the handle to write it with."""
        if msgtype not in TYPESTORE.types:
            raise BagError(f'cannot record {topic}: message type {msgtype} is not a ROS 2 Jazzy '
                           f'type')
        return self._writer.add_connection(topic, msgtype, typestore=TYPESTORE,
                                           offered_qos_profiles=list(offered_qos))

    def write(self, connection: Connection, log_time_ns: int, data: bytes) -> None:
        """Append serialized (CDR) ``data`` received at ``log_time_ns``."""
        self._writer.write(connection, log_time_ns, data)

    def write_message(self, connection: Connection, log_time_ns: int, msg) -> None:
        """Serialize the rosbags message ``msg`` and append it."""
        self.write(connection, log_time_ns, TYPESTORE.serialize_cdr(msg, connection.msgtype))

    def close(self) -> None:
        """Finish the bag (index, statistics, ``metadata.yaml``); idempotent."""
        if self._open:
            self._open = False
            self._writer.close()

    def __enter__(self) -> 'BagWriter':
        return self.open()

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self._open = False
            self._writer.abort()


def write_wrench_series(path, series: WrenchSeries, component: str = 'torque.z',
                        storage: str = 'mcap') -> None:
    """Write ``series`` as a one-topic bag, log time = header stamp (a clean recording)."""
    with BagWriter(path, storage) as bag:
        conn = bag.add_topic(series.topic, WRENCH_STAMPED)
        for stamp, value in zip(series.stamps_ns.tolist(), series.values.tolist()):
            bag.write_message(conn, stamp, wrench_message(stamp, series.frame_id, component, value))
