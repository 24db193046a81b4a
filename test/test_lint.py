# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The house rules anyone can check: ruff's lint and format (ruff.toml), and the licence header
on every Python file (scripts/add_license_headers.py), over the whole repository."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RUFF = Path(sys.executable).parent / 'ruff'

needs_ruff = pytest.mark.skipif(not RUFF.exists(), reason='ruff is installed by make setup')


@needs_ruff
def test_ruff_lint_is_clean():
    done = subprocess.run(
        [str(RUFF), 'check', '--no-cache', '.'], cwd=ROOT, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stdout + done.stderr


@needs_ruff
def test_ruff_format_is_clean():
    done = subprocess.run(
        [str(RUFF), 'format', '--check', '--no-cache', '.'],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stdout + done.stderr


def test_every_python_file_has_the_licence_header():
    done = subprocess.run(
        [sys.executable, str(ROOT / 'scripts' / 'add_license_headers.py'), '--check'],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, 'no licence header: ' + done.stdout
