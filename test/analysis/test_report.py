# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``analyze --report DIR [--geometry FILE]`` (analysis/report.py): the page holds every mode the
JSONL reports with its frequency and damping, its images exist and decode, a shape on the
geometry is an animation of that shape; the page opens in headless Chromium without a broken
image or a console message (skipped where Chromium is absent: .ci/run installs it)."""

from __future__ import annotations

import contextlib
import html
import io
import json
import re
import shlex
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from vib_estimator.analysis.summary import summarise_modes
from vib_estimator.cli import main
from vib_estimator.sim.frame import modal_record

MODES = [(1.0, 0.02, 1.0), (2.5, 0.02, 0.5)]
SHAPES = np.array([[1.0, 0.5], [0.6, -0.9], [0.2, 0.8]])
AMBIENT = ['--excitation', 'ambient', '--ambient-window-s', '40']
#: a three-point mast, one channel a point, along x
GEOMETRY = """
name: test mast
points: {base: [0, 0, 0], p1: [0, 0, 1], p2: [0, 0, 2], p3: [0, 0, 3]}
channels:
  a: {point: p3, direction: x}
  b: {point: p2, direction: x}
  c: {point: p1, direction: [2, 0, 0]}
lines: [[base, p1], [p1, p2], [p2, p3]]
fixed: [base]
"""
#: where the screenshot of the rendered page is kept
SHOTS = Path(__file__).resolve().parents[2] / 'out' / 'test_report'


def run(*argv):
    """(exit code, stdout, stderr) of the command line ``argv``."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope='module')
def record(tmp_path_factory):
    folder = tmp_path_factory.mktemp('report')
    t, y = modal_record(160.0, 20.0, MODES, SHAPES, snr_db=20.0, seed=4)
    path = folder / 'three.csv'
    np.savetxt(path, np.column_stack((t, y)), delimiter=',', header='time,a,b,c', comments='')
    (folder / 'mast.yaml').write_text(GEOMETRY)
    return path


@pytest.fixture(scope='module')
def report(record):
    folder = record.parent / 'page'  # (the JSONL and the page of one run)
    geometry = record.parent / 'mast.yaml'
    code, out, err = run(
        'analyze', str(record), '--columns', 'all', *AMBIENT, '--report', str(folder),
        '--geometry', str(geometry),
    )  # fmt: skip
    assert code == 0, err
    rows = [json.loads(line) for line in out.splitlines()]
    return folder, rows, err


def images_of(page: Path) -> list[Path]:
    return [page.parent / src for src in re.findall(r'<img src="([^"]+)"', page.read_text())]


def test_every_mode_of_the_jsonl_is_in_the_page_with_f_and_zeta(report):
    folder, rows, err = report
    page = (folder / 'index.html').read_text()
    modes = summarise_modes(
        [r['frequency_hz'] for r in rows], [r['damping'] for r in rows], [r['mode'] for r in rows]
    )
    assert len(modes) == len(MODES)
    for m, (f, _, _) in zip(modes, MODES):
        assert abs(m.frequency_hz / f - 1) < 0.02
        cell = re.search(rf'data-mode="{m.mode}">.*?</tr>', page, re.S).group(0)
        assert f'{m.frequency_hz:.4f} ±' in cell and f'{m.damping:.4f} ±' in cell
    command = shlex.join(['vib-estimator', 'analyze', str(folder.parent / 'three.csv')])
    assert html.escape(command + ' --columns all ' + ' '.join(AMBIENT)) in page
    assert 'ros2 run vib_estimator shaper_node' in page and f'report written to {folder}' in err


def test_images_exist_decode_and_each_mode_is_animated(report):
    folder, _, _ = report
    images = images_of(folder / 'index.html')
    names = {p.name for p in images}
    assert {'spectrum.png', 'stabilisation.png', 'tracks.png', 'mac.png'} <= names
    for path in images:
        with Image.open(path) as im:
            im.load()
            assert im.size[0] > 200 and im.size[1] > 150
    for k in range(1, len(MODES) + 1):
        with Image.open(folder / f'shape_mode{k}.gif') as im:
            assert im.n_frames > 4


def test_without_geometry_each_shape_is_a_bar_plot(record, tmp_path):
    code, _, err = run(
        'analyze', str(record), '--columns', 'a,b', *AMBIENT, '--report', str(tmp_path)
    )
    assert code == 0, err
    names = {p.name for p in images_of(tmp_path / 'index.html')}
    assert 'shape_mode1.png' in names and not any(n.endswith('.gif') for n in names)


def test_no_estimate_says_why(tmp_path):
    t = np.arange(2000) / 20.0
    path = tmp_path / 'flat.csv'
    np.savetxt(path, np.column_stack((t, np.ones_like(t))), delimiter=',', header='t,y')
    code, out, _ = run('analyze', str(path), *AMBIENT, '--report', str(tmp_path / 'r'))
    page = (tmp_path / 'r' / 'index.html').read_text()
    assert code == 0 and not out
    assert 'No estimate.' in page and 'the signal is constant' in page
    assert all(p.exists() for p in images_of(tmp_path / 'r' / 'index.html'))


@pytest.mark.parametrize(
    'geometry, message',
    [
        ('points: {a: [0, 0]}\nchannels: {}', r'point a must be \[x, y, z\]'),
        (GEOMETRY.replace('  c: {point: p1, direction: [2, 0, 0]}\n', ''), 'does not place .*c'),
    ],
)
def test_bad_geometry_is_one_error_line(record, tmp_path, geometry, message):
    path = tmp_path / 'g.yaml'
    path.write_text(geometry)
    code, out, err = run(
        'analyze', str(record), '--columns', 'all', *AMBIENT, '--report', str(tmp_path / 'r'),
        '--geometry', str(path),
    )  # fmt: skip
    assert code == 2 and not out and len(err.splitlines()) == 1
    assert re.search('error: geometry .*' + message, err)


def test_geometry_without_report_is_an_error(record):
    code, _, err = run('analyze', str(record), '--geometry', 'x.yaml')
    assert code == 2 and 'give --report too' in err


# ---- as a person would see it ------------------------------------------------------------------
CHROMIUM = shutil.which('chromium') or shutil.which('chromium-browser')
#: the flags of a quiet, isolated headless run
CHROMIUM_FLAGS = (
    '--headless',
    '--no-sandbox',
    '--disable-gpu',
    '--disable-background-networking',
    '--no-first-run',
    '--disable-component-update',
    '--disable-sync',
    '--enable-logging=stderr',
    '--v=0',
)
#: appended to a copy of the page (the report itself has no script): lists the images that did
#: not load
PROBE = (
    "<script>window.addEventListener('load',function(){var b=[],im=document.images;"
    'for(var i=0;i<im.length;i++){if(!(im[i].complete&&im[i].naturalWidth>0))'
    "b.push(im[i].getAttribute('src'));}var p=document.createElement('pre');p.id='probe';"
    "p.textContent='images='+im.length+' broken='+b.join(',')+';';"
    'document.body.appendChild(p);});</script>'
)


def chromium(tmp_path: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [CHROMIUM, *CHROMIUM_FLAGS, f'--user-data-dir={tmp_path / "profile"}', *args],
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.mark.skipif(CHROMIUM is None, reason='chromium is not installed (.ci/run installs it)')
def test_page_renders_in_chromium_without_broken_image_or_console_message(report, tmp_path):
    folder, _, _ = report
    page = folder / 'index.html'
    probe = folder / 'probe.html'
    probe.write_text(page.read_text().replace('</body>', PROBE + '</body>'))
    try:
        run_ = chromium(tmp_path, '--virtual-time-budget=5000', '--dump-dom', probe.as_uri())
    finally:
        probe.unlink()
    found = re.search(r'images=(\d+) broken=([^;]*);', run_.stdout)
    assert found, run_.stderr[-2000:]
    assert int(found.group(1)) == len(images_of(page)) > 0 and found.group(2) == ''
    console = [line for line in run_.stderr.splitlines() if ':CONSOLE' in line]
    assert not console
    SHOTS.mkdir(parents=True, exist_ok=True)
    shot = SHOTS / 'report.png'
    chromium(tmp_path, '--hide-scrollbars', '--window-size=1200,3000', f'--screenshot={shot}',
             page.as_uri())  # fmt: skip
    with Image.open(shot) as im:
        assert im.size == (1200, 3000)
        assert len(im.convert('L').getcolors(1 << 16) or ()) > 16  # not a blank page


@pytest.mark.skipif(CHROMIUM is None, reason='chromium is not installed (.ci/run installs it)')
def test_the_probe_sees_a_broken_image(report, tmp_path):
    """The check above can fail: a page with a missing image is caught."""
    folder, _, _ = report
    bad = tmp_path / 'bad.html'
    bad.write_text(f'<html><body><img src="missing.png">{PROBE}</body></html>')
    out = chromium(tmp_path, '--virtual-time-budget=5000', '--dump-dom', bad.as_uri()).stdout
    assert 'images=1 broken=missing.png;' in out


def test_a_mode_whose_frequency_moved_is_listed_and_marked_per_stretch(tmp_path):
    """Three tip masses (1.64, 1.33, 1.15 Hz) of one mode: three rows and three marks, never one
    median across them."""
    from vib_estimator.analysis.report import Record, write_report
    from vib_estimator.core import EstimatorConfig
    from vib_estimator.core.estimator import Estimate, EstimateArrays

    truth = [(0.0, 1.64), (10.0, 1.33), (20.0, 1.15)]
    est = [
        Estimate(t0 + k, f * (1 + 1e-3 * (k % 2)), 1.0, 500, 0.99, 1.0)
        for t0, f in truth
        for k in range(1, 6)
    ]
    t = np.arange(0, 30, 0.002)
    y = np.sin(2 * np.pi * 1.3 * t)
    record = Record('x.csv', 'vib-estimator analyze x.csv', ('y',), t, y,
                    EstimateArrays.of(est), EstimatorConfig(), {})  # fmt: skip
    page = write_report(tmp_path, record).read_text()
    rows = re.findall(r'\(t ([\d.]+)–([\d.]+) s\)</td><td>([\d.]+) ', page)
    assert len(rows) == 3
    for (t0, f), (first, last, shown) in zip(truth, rows):
        assert (float(first), float(last)) == (t0 + 1, t0 + 5)
        assert abs(float(shown) / f - 1) < 2e-3
    assert page.count('data-mode="0"') == 3
    assert 'for the last stretch, from t = 21 s' in page  # the shaper: the last mass's
