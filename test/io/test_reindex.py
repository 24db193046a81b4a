# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""io.reindex and `vib-estimator reindex`: metadata.yaml rebuilt from the storage files, cut MCAP
files repaired, independent readers (rosbags, mcap) agree."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
from mcap.reader import make_reader
from rosbags.rosbag2 import Reader

from vib_estimator.cli import main
from vib_estimator.io.bags import TYPESTORE, BagError, BagReader, BagWriter
from vib_estimator.io.reindex import reindex, scan_mcap

# ../shared relative to the repo; VIB_SHARED names it elsewhere (a worktree)
SHARED_BAGS = (
    Path(os.environ.get('VIB_SHARED', Path(__file__).resolve().parents[3] / 'shared'))
    / 'ros2-bags'
)
STRING = 'std_msgs/msg/String'


def string_bag(path, n, storage='mcap', flush_every=0, **limits):
    """``n`` String messages on /a and /b alternately, log times 1 ns apart; the payloads."""
    payloads = []
    with BagWriter(path, storage, **limits) as bag:
        conns = [bag.add_topic('/a', STRING), bag.add_topic('/b', STRING)]
        for i in range(n):
            data = TYPESTORE.serialize_cdr(TYPESTORE.types[STRING](data=f'message {i}'), STRING)
            bag.write(conns[i % 2], 1_000 + i, data)
            payloads.append(data)
            if flush_every and i % flush_every == flush_every - 1:
                bag.flush()
    return payloads


def rosbags_payloads(path):
    with Reader(path) as reader:
        return [bytes(data) for _, _, data in reader.messages()]


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_reindex_rebuilds_a_lost_metadata_yaml_of_a_split_bag(tmp_path, storage):
    payloads = string_bag(tmp_path / 'bag', 300, storage, max_bag_duration_ns=100)
    files = sorted(p.name for p in (tmp_path / 'bag').iterdir() if p.name != 'metadata.yaml')
    assert len(files) >= 3 and files[0] == f'bag_0{".mcap" if storage == "mcap" else ".db3"}'
    before = (tmp_path / 'bag' / 'metadata.yaml').read_text()
    (tmp_path / 'bag' / 'metadata.yaml').unlink()
    with pytest.raises(BagError, match=r'no metadata.yaml: run `vib-estimator reindex'):
        BagReader(tmp_path / 'bag')
    result = reindex(tmp_path / 'bag')
    assert [f.count for f in result.files] and sum(f.count for f in result.files) == 300
    assert not result.cuts
    assert (tmp_path / 'bag' / 'metadata.yaml').read_text() == before  # same as written
    assert rosbags_payloads(tmp_path / 'bag') == payloads


def mcap_file(path):
    (file,) = [p for p in path.iterdir() if p.suffix == '.mcap']
    return file


@pytest.mark.parametrize('fraction', [0.3, 0.6, 0.97])
def test_reindex_of_a_truncated_mcap_keeps_what_is_complete(tmp_path, fraction):
    """A file cut anywhere: the complete messages come back, a prefix of what was written."""
    payloads = string_bag(tmp_path / 'bag', 400, flush_every=50)
    file = mcap_file(tmp_path / 'bag')
    data = file.read_bytes()
    file.write_bytes(data[: int(len(data) * fraction)])
    with pytest.raises(BagError, match='corrupt or truncated'):
        BagReader(tmp_path / 'bag')
    result = reindex(tmp_path / 'bag')
    (cut,) = result.cuts
    assert (
        ('cut at byte' in cut or 'summary section cut' in cut)
        and f'of {int(len(data) * fraction)}' in cut
        or f'{int(len(data) * fraction)} bytes' in cut
    )
    kept = rosbags_payloads(tmp_path / 'bag')
    assert kept == payloads[: len(kept)]
    assert len(kept) >= int(400 * fraction) - 60  # at most one flush (50) and a record lost
    assert f'kept {len(kept)} complete messages' in cut
    with open(file, 'rb') as f:  # an independent MCAP reader reads the repaired file
        assert sum(1 for _ in make_reader(f).iter_messages()) == len(kept)
    with BagReader(tmp_path / 'bag') as bag:
        assert bag.message_count == len(kept)


def test_scan_of_a_cut_uncompressed_chunk_keeps_its_complete_messages(tmp_path):
    payloads = string_bag(tmp_path / 'bag', 100)  # one chunk, written at close
    data = mcap_file(tmp_path / 'bag').read_bytes()
    chunk = 8 + 9 + int.from_bytes(data[9:17], 'little')  # after magic and header record
    assert data[chunk] == 0x06
    content = scan_mcap(data[: chunk + 2000])
    assert content.complete_bytes == chunk
    assert [m[2] for m in content.messages] == payloads[: len(content.messages)]
    assert 10 < len(content.messages) < 100
    assert scan_mcap(data[:5]).messages == [] and scan_mcap(b'').complete_bytes == 0


def test_reindex_command_prints_the_cut_and_refuses_non_bags(tmp_path, capsys):
    string_bag(tmp_path / 'bag', 50)
    file = mcap_file(tmp_path / 'bag')
    file.write_bytes(file.read_bytes()[:3000])
    assert main(['reindex', str(tmp_path / 'bag')]) == 0
    out = capsys.readouterr().out
    assert 'reindexed' in out and '/a (std_msgs/msg/String)' in out and 'cut at byte' in out
    (tmp_path / 'empty').mkdir()
    (tmp_path / 'mixed').mkdir()
    (tmp_path / 'mixed' / 'x.mcap').write_bytes(b'')
    (tmp_path / 'mixed' / 'y.db3').write_bytes(b'')
    for path, message in (
        (tmp_path / 'empty', 'holds no .mcap or .db3 file'),
        (tmp_path / 'mixed', 'mixes .mcap and .db3 files'),
        (file, 'not a directory'),
    ):
        assert main(['reindex', str(path)]) == 2
        err = capsys.readouterr().err
        assert err.startswith('error: ') and message in err and err.count('\n') == 1


@pytest.mark.skipif(not SHARED_BAGS.is_dir(), reason='../shared/ros2-bags is absent')
@pytest.mark.parametrize(
    'name, count', [('mcap_wbag', 6074), ('sqlite3_wbag', 6074), ('mcap_talker', 20)]
)
def test_reindex_of_rosbag2_bags_counts_every_message(tmp_path, name, count):
    shutil.copytree(SHARED_BAGS / name, tmp_path / name)
    (tmp_path / name / 'metadata.yaml').unlink()
    for file in (tmp_path / name).iterdir():
        file.chmod(0o644)
    result = reindex(tmp_path / name)
    assert sum(f.count for f in result.files) == count
    assert len(rosbags_payloads(tmp_path / name)) == count  # rosbags trusts the new metadata


@pytest.mark.parametrize(
    'content, message',
    [(b'', 'is empty (0 bytes)'), (b'not an mcap file', 'does not start with the MCAP')],
)
def test_reindex_of_a_file_that_is_not_mcap_is_an_error_and_leaves_it(
    tmp_path, capsys, content, message
):
    """A 0-byte .mcap used to be "0 messages, index rebuilt" and rewritten (issue 22, case 8)."""
    (tmp_path / 'bag').mkdir()
    file = tmp_path / 'bag' / 'bag_0.mcap'
    file.write_bytes(content)
    assert main(['reindex', str(tmp_path / 'bag')]) == 2
    captured = capsys.readouterr()
    assert captured.out == '' and captured.err.count('\n') == 1
    assert captured.err.startswith('error: ') and message in captured.err
    assert file.read_bytes() == content and not (tmp_path / 'bag' / 'metadata.yaml').exists()


def test_reindex_drops_a_damaged_chunk_and_says_so(tmp_path):
    """A cut file whose first chunk's CRC fails: its messages are not rewritten as good ones."""
    from vib_estimator.io import mcap

    with BagWriter(tmp_path / 'bag') as bag:
        conn = bag.add_topic('/a', 'std_msgs/msg/String')
        for i in range(3000):
            bag.write_message(
                conn,
                1000 + i,
                TYPESTORE.types['std_msgs/msg/String'](data=f'message {i:04d} ' + 'x' * 40),
            )
    file = mcap_file(tmp_path / 'bag')
    _, _, start, length, _ = mcap.read_summary(file).chunks[0]
    data = bytearray(file.read_bytes())
    data[start + length // 2] ^= 0xFF
    file.write_bytes(bytes(data[: len(data) - 100]))  # cut: reindex must scan it
    result = reindex(tmp_path / 'bag')
    assert 'damaged chunk(s) dropped' in result.summary()
    with BagReader(tmp_path / 'bag') as bag:
        kept = [m.data for m in bag.messages()]
        assert 0 < len(kept) < 3000 and bag.corrupt == 0
    texts = {TYPESTORE.deserialize_cdr(d, 'std_msgs/msg/String').data[:12] for d in kept}
    assert texts <= {f'message {i:04d}' for i in range(3000)}
