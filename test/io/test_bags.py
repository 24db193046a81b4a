# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""bag_io: round trips through every storage layout, clear BagErrors, the shipped bags."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from vib_estimator.io.bags import (
    TYPESTORE,
    WRENCH_STAMPED,
    BagError,
    BagReader,
    BagWriter,
    WrenchSeries,
    read_wrench_series,
    wrench_message,
    write_wrench_series,
)

BAGS = Path(__file__).resolve().parents[2] / 'bags'

#: shipped bag -> (samples on /coupling_torque, ground-truth messages, true frequencies in Hz)
SHIPPED = {
    'arm_5_3': (5000, 100, (1.3306,)),
    'arm_5_5': (9000, 180, (1.6395, 1.3306, 1.1482)),
    'fig1': (3000, 60, (1.5915,)),
}


def series(n=500, topic='/coupling_torque'):
    stamps = 1_700_000_000_123_456_789 + np.arange(n, dtype=np.int64) * 2_000_000
    return WrenchSeries(stamps, np.sin(np.arange(n) * 0.05) + 1e-12, 'arm_base', topic)


@pytest.fixture
def mcap_bag(tmp_path):
    path = tmp_path / 'bag'
    write_wrench_series(path, series())
    return path


def assert_same(read, written):
    np.testing.assert_array_equal(read.stamps_ns, written.stamps_ns)
    np.testing.assert_array_equal(read.values, written.values)  # exact floats
    assert read.stamps_ns.dtype == np.int64 and read.values.dtype == np.float64
    assert (read.frame_id, read.topic) == (written.frame_id, written.topic)


@pytest.mark.parametrize('storage, file_name', [('mcap', 'bag.mcap'), ('sqlite3', 'bag.db3')])
def test_round_trip_directory_and_bare_file(tmp_path, storage, file_name):
    written = series()
    write_wrench_series(tmp_path / 'bag', written, storage=storage)
    assert_same(read_wrench_series(tmp_path / 'bag'), written)
    assert_same(read_wrench_series(tmp_path / 'bag' / file_name, '/coupling_torque'), written)


def test_other_component_and_topic_choice(tmp_path):
    written = series(topic='/wrist')
    write_wrench_series(tmp_path / 'bag', written, component='force.y')
    read = read_wrench_series(tmp_path / 'bag', '/wrist', 'force.y')
    np.testing.assert_array_equal(read.values, written.values)
    assert not read_wrench_series(tmp_path / 'bag', '/wrist', 'torque.z').values.any()
    with pytest.raises(
        ValueError, match='component of geometry_msgs/msg/WrenchStamped must be one of'
    ):
        read_wrench_series(tmp_path / 'bag', component='torque.w')


def test_metadata_is_rosbag2_version_8_with_qos_and_definitions(mcap_bag):
    text = (mcap_bag / 'metadata.yaml').read_text()
    assert 'version: 8' in text and 'storage_identifier: mcap' in text
    assert 'type_description_hash' in text and 'RIHS01_' in text
    with open(mcap_bag / 'bag.mcap', 'rb') as f:  # an independent MCAP reader agrees
        reader = make_reader(f)
        summary = reader.get_summary()
        assert reader.get_header().profile == 'ros2'
        (channel,) = summary.channels.values()
        (schema,) = summary.schemas.values()
        assert (schema.name, schema.encoding) == (WRENCH_STAMPED, 'ros2msg')
        assert b'MSG: geometry_msgs/Wrench' in schema.data
        assert 'reliability: 1' in channel.metadata['offered_qos_profiles']
        assert summary.statistics.message_count == 500
        assert sum(1 for _ in reader.iter_messages()) == 500


def test_reader_lists_topics_and_yields_raw_messages_in_order(tmp_path):
    with BagWriter(tmp_path / 'bag') as bag:
        a = bag.add_topic('/a', 'std_msgs/msg/Float64')
        b = bag.add_topic('/b', 'std_msgs/msg/String')
        for i in range(10):
            bag.write_message(
                a if i % 2 else b,
                1000 + i,
                TYPESTORE.types['std_msgs/msg/Float64'](data=float(i))
                if i % 2
                else TYPESTORE.types['std_msgs/msg/String'](data=str(i)),
            )
    with BagReader(tmp_path / 'bag') as reader:
        assert {t: (i.msgtype, i.count) for t, i in reader.topics.items()} == {
            '/a': ('std_msgs/msg/Float64', 5),
            '/b': ('std_msgs/msg/String', 5),
        }
        assert (reader.start_ns, reader.end_ns, reader.message_count) == (1000, 1009, 10)
        messages = list(reader.messages())
        assert [m.log_time_ns for m in messages] == list(range(1000, 1010))
        assert [m.topic for m in messages[:2]] == ['/b', '/a']
        assert TYPESTORE.deserialize_cdr(messages[1].data, messages[1].msgtype).data == 1.0
        assert [m.log_time_ns for m in reader.messages(['/a'], start_ns=1005)] == [
            1005,
            1007,
            1009,
        ]


def bad_bag(tmp_path, kind, mcap_bag):
    """Build one kind of unreadable bag and return its path."""
    if kind == 'missing':
        return tmp_path / 'nowhere'
    if kind == 'random_mcap':
        path = tmp_path / 'random.mcap'
        path.write_bytes(np.random.default_rng(1).bytes(4096))
        return path
    if kind == 'random_db3':
        path = tmp_path / 'random.db3'
        path.write_bytes(np.random.default_rng(2).bytes(4096))
        return path
    if kind == 'truncated_dir':
        data = (mcap_bag / 'bag.mcap').read_bytes()
        (mcap_bag / 'bag.mcap').write_bytes(data[: len(data) // 2])
        return mcap_bag
    if kind == 'not_a_bag_dir':
        (tmp_path / 'plain').mkdir()
        return tmp_path / 'plain'
    if kind == 'text_file':
        (tmp_path / 'notes.txt').write_text('hello')
        return tmp_path / 'notes.txt'
    if kind == 'numpy_file':
        np.save(tmp_path / 'rec.npy', np.zeros((2, 100)))
        return tmp_path / 'rec.npy'
    if kind == 'empty':
        with BagWriter(tmp_path / 'empty') as bag:
            bag.add_topic('/coupling_torque', WRENCH_STAMPED)
        return tmp_path / 'empty'
    raise AssertionError(kind)


@pytest.mark.parametrize(
    'kind, message',
    [
        ('missing', 'does not exist'),
        ('random_mcap', 'corrupt or truncated'),
        ('random_db3', 'corrupt or truncated'),
        ('truncated_dir', r'corrupt or truncated bag\?; `vib-estimator reindex .*` rebuilds it'),
        ('not_a_bag_dir', 'has no metadata.yaml'),
        ('text_file', 'is not a bag'),
        (
            'numpy_file',
            r'is not a bag: .* a NumPy array: write it as one, e\.g\. .*numpy\.savetxt',
        ),
        ('empty', 'contains no messages'),
    ],
)
def test_unreadable_bags_raise_one_clear_sentence(tmp_path, mcap_bag, kind, message):
    path = bad_bag(tmp_path, kind, mcap_bag)
    with pytest.raises(BagError, match=message) as err:
        read_wrench_series(path)
    text = str(err.value)
    assert str(path) in text and '\n' not in text


def test_truncated_bare_mcap_file(tmp_path, mcap_bag):
    data = (mcap_bag / 'bag.mcap').read_bytes()
    for cut in (len(data) // 2, len(data) - 10, 20):
        path = tmp_path / f'cut{cut}.mcap'
        path.write_bytes(data[:cut])
        with pytest.raises(BagError, match='corrupt or truncated'):
            read_wrench_series(path)


def test_wrong_topic_and_type_name_the_available_topics(tmp_path, mcap_bag):
    with pytest.raises(
        BagError,
        match=r"no topic '/nope'; its topics are /coupling_torque "
        r'\(geometry_msgs/msg/WrenchStamped\)',
    ):
        read_wrench_series(mcap_bag, '/nope')
    with BagWriter(tmp_path / 'mixed') as bag:
        conn = bag.add_topic('/f', 'std_msgs/msg/Float64')
        bag.write_message(conn, 1, TYPESTORE.types['std_msgs/msg/Float64'](data=1.0))
    with pytest.raises(BagError, match='has type std_msgs/msg/Float64, not geometry_msgs'):
        read_wrench_series(tmp_path / 'mixed', '/f')
    with pytest.raises(
        BagError,
        match=r'no geometry_msgs/msg/WrenchStamped topic; its topics '
        r'are /f \(std_msgs/msg/Float64\)',
    ):
        read_wrench_series(tmp_path / 'mixed')


def test_several_wrench_topics_need_a_choice(tmp_path):
    with BagWriter(tmp_path / 'two') as bag:
        for topic in ('/left', '/right'):
            bag.write_message(
                bag.add_topic(topic, WRENCH_STAMPED),
                1,
                wrench_message(1_000_000_002, 'f', 'torque.z', 3.5),
            )
    with pytest.raises(BagError, match='several .* choose one: /left, /right'):
        read_wrench_series(tmp_path / 'two')
    read = read_wrench_series(tmp_path / 'two', '/right')
    assert read.stamps_ns.tolist() == [1_000_000_002] and read.values.tolist() == [3.5]


def test_writer_refuses_existing_directory_and_unknown_type(tmp_path, mcap_bag):
    with pytest.raises(BagError, match='exists already'):
        BagWriter(mcap_bag)
    with BagWriter(tmp_path / 'new') as bag:
        with pytest.raises(BagError, match='not a ROS 2 Jazzy type'):
            bag.add_topic('/x', 'my_pkg/msg/Custom')


@pytest.mark.parametrize('name', sorted(SHIPPED))
def test_shipped_bags(name):
    samples, truths, frequencies = SHIPPED[name]
    read = read_wrench_series(BAGS / name)
    assert len(read) == samples and read.frame_id == 'arm_base'
    assert read.stamps_ns[0] == 1_700_000_000 * 10**9
    assert np.all(np.diff(read.stamps_ns) > 0)
    with BagReader(BAGS / name) as bag:
        assert bag.topics['/vibration/ground_truth'].count == truths
        truth = sorted(
            {
                round(TYPESTORE.deserialize_cdr(m.data, m.msgtype).data, 4)
                for m in bag.messages(['/vibration/ground_truth'])
            },
            reverse=True,
        )
    assert tuple(truth) == tuple(sorted(frequencies, reverse=True))


def test_make_bags_is_deterministic(tmp_path):
    import runpy

    script = runpy.run_path(str(BAGS.parent / 'scripts' / 'make_bags.py'))
    assert script['main'](['--out', str(tmp_path)]) == 0
    for name in SHIPPED:
        for shipped in (BAGS / name).iterdir():
            assert (tmp_path / name / shipped.name).read_bytes() == shipped.read_bytes(), shipped


# -- bags written by rosbag2 itself, split bags, crash safety -------------------------------------

# ../shared relative to the repo; VIB_SHARED names it elsewhere (a worktree)
SHARED_BAGS = (
    Path(os.environ.get('VIB_SHARED', Path(__file__).resolve().parents[3] / 'shared'))
    / 'ros2-bags'
)
needs_shared = pytest.mark.skipif(not SHARED_BAGS.is_dir(), reason='../shared/ros2-bags is absent')
ROSBAG2_BAGS = ['mcap_talker', 'sqlite3_talker', 'mcap_wbag', 'sqlite3_wbag']


def storage_counts(directory: Path) -> dict:
    """Messages per topic counted in the storage files themselves (mcap library, SQL)."""
    import sqlite3

    counts = {}
    for file in sorted(directory.iterdir()):
        if file.suffix == '.mcap':
            with open(file, 'rb') as f:
                for _, channel, _ in make_reader(f).iter_messages():
                    counts[channel.topic] = counts.get(channel.topic, 0) + 1
        elif file.suffix == '.db3':
            conn = sqlite3.connect(f'file:{file}?immutable=1', uri=True)  # no -wal/-shm
            for topic, n in conn.execute(
                'SELECT topics.name, count(*) FROM messages JOIN topics '
                'ON messages.topic_id = topics.id GROUP BY topics.name'
            ):
                counts[topic] = counts.get(topic, 0) + n
            conn.close()
    return counts


@needs_shared
@pytest.mark.parametrize('name', ROSBAG2_BAGS)
def test_rosbag2_bags_read_completely_in_log_time_order(name):
    expected = storage_counts(SHARED_BAGS / name)
    assert sum(expected.values()) == (6074 if 'wbag' in name else 20)  # SOURCE.md
    with BagReader(SHARED_BAGS / name) as bag:
        assert {t: i.count for t, i in bag.topics.items() if i.count} == expected
        messages = list(bag.messages())
        from_start = list(bag.messages(start_ns=bag.start_ns))  # the filter the replayer uses
        assert bag.message_count == len(messages) == len(from_start) == sum(expected.values())
        times = [m.log_time_ns for m in messages]
        assert times == sorted(times) and (times[0], times[-1]) == (bag.start_ns, bag.end_ns)
        middle = times[len(times) // 2]
        assert [m.log_time_ns for m in bag.messages(start_ns=middle)] == [
            t for t in times if t >= middle
        ]


@needs_shared
def test_rosbag2_empty_bag_has_nothing_to_read():
    with pytest.raises(BagError, match='empty_bag contains no messages'):
        BagReader(SHARED_BAGS / 'empty_bag')


def test_start_filter_on_a_split_bag_with_close_log_times_and_wrong_metadata(tmp_path):
    """rosbag2 wrote split bags whose metadata.yaml has the last file's start (ros2/rosbag2#841):
    the start and every count come from the storage files, so nothing is skipped."""
    float64 = TYPESTORE.types['std_msgs/msg/Float64']
    with BagWriter(tmp_path / 'bag', max_bag_size=3000) as bag:
        conns = [bag.add_topic(t, 'std_msgs/msg/Float64') for t in ('/a', '/b', '/c')]
        for i in range(600):  # log times 1 ns apart, several messages per ns
            bag.write_message(conns[i % 3], 5000 + i // 2, float64(data=float(i)))
    assert len(bag.files) >= 4 and bag.files[0].name == 'bag_0.mcap'
    meta = tmp_path / 'bag' / 'metadata.yaml'
    text = meta.read_text().replace(
        'nanoseconds_since_epoch: 5000\n',
        f'nanoseconds_since_epoch: {bag.files[-1].start_ns}\n',
        1,
    )
    meta.write_text(text)
    with BagReader(tmp_path / 'bag') as reader:
        assert reader.start_ns == 5000 and reader.end_ns == 5299
        values = [
            TYPESTORE.deserialize_cdr(m.data, m.msgtype).data
            for m in reader.messages(start_ns=reader.start_ns)
        ]
        assert values == [float(i) for i in range(600)]  # all, in order, ties in file order
        late_a = [float(i) for i in range(600) if i % 3 == 0 and 5000 + i // 2 >= 5100]
        assert [
            TYPESTORE.deserialize_cdr(m.data, m.msgtype).data
            for m in reader.messages(['/a'], start_ns=5100)
        ] == late_a


def test_split_by_duration_names_files_like_rosbag2(tmp_path):
    with BagWriter(tmp_path / 'rec', 'sqlite3', max_bag_duration_ns=1_000) as bag:
        conn = bag.add_topic('/a', 'std_msgs/msg/Float64')
        for i in range(50):
            bag.write_message(conn, i * 100, TYPESTORE.types['std_msgs/msg/Float64'](data=i))
    assert [f.name for f in bag.files] == [f'rec_{i}.db3' for i in range(5)]
    assert [f.count for f in bag.files] == [10] * 5
    assert storage_counts(tmp_path / 'rec') == {'/a': 50}
    with BagReader(tmp_path / 'rec') as reader:
        assert [m.log_time_ns for m in reader.messages()] == [i * 100 for i in range(50)]


def test_old_style_type_names_are_read_as_pkg_msg_name(tmp_path):
    from rosbags.rosbag2 import StoragePlugin, Writer

    with Writer(tmp_path / 'old', version=8, storage_plugin=StoragePlugin.SQLITE3) as bag:
        conn = bag.add_connection(
            '/s', 'std_msgs/String', msgdef='string data', rihs01='RIHS01_' + '0' * 64
        )
        bag.write(
            conn,
            1,
            TYPESTORE.serialize_cdr(
                TYPESTORE.types['std_msgs/msg/String'](data='x'), 'std_msgs/msg/String'
            ),
        )
    with BagReader(tmp_path / 'old') as reader:
        assert reader.topics['/s'].msgtype == 'std_msgs/msg/String'
        assert [m.msgtype for m in reader.messages()] == ['std_msgs/msg/String']


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_flushed_messages_are_in_the_file_before_close(tmp_path, storage):
    """What a SIGKILL after flush() leaves: the file as it is on disk, reindexed."""
    import shutil

    from vib_estimator.io.reindex import reindex

    bag = BagWriter(tmp_path / 'bag', storage).open()
    conn = bag.add_topic('/a', 'std_msgs/msg/Float64')
    for i in range(30):
        bag.write_message(conn, i, TYPESTORE.types['std_msgs/msg/Float64'](data=i))
    bag.flush()
    bag.write_message(conn, 99, TYPESTORE.types['std_msgs/msg/Float64'](data=99.0))  # not flushed
    shutil.copytree(tmp_path / 'bag', tmp_path / 'copy')  # the disk at the moment of the kill
    bag.close()
    assert '- bag.' in (tmp_path / 'copy' / 'metadata.yaml').read_text()  # written at start
    reindex(tmp_path / 'copy')
    with BagReader(tmp_path / 'copy') as reader:
        assert [m.log_time_ns for m in reader.messages()] == list(range(30))


def test_message_compressed_bag(tmp_path):
    from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer

    writer = Writer(tmp_path / 'zbag', version=8, storage_plugin=StoragePlugin.MCAP)
    writer.set_compression(CompressionMode.MESSAGE, CompressionFormat.ZSTD)
    float64 = TYPESTORE.types['std_msgs/msg/Float64']
    with writer:
        conn = writer.add_connection('/f', 'std_msgs/msg/Float64', typestore=TYPESTORE)
        for i in range(5):
            writer.write(conn, i, TYPESTORE.serialize_cdr(float64(data=i), conn.msgtype))
    with BagReader(tmp_path / 'zbag') as reader:
        assert [TYPESTORE.deserialize_cdr(m.data, m.msgtype).data for m in reader.messages()] == [
            0.0,
            1.0,
            2.0,
            3.0,
            4.0,
        ]
