# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Output paths of the command line, checked before any work starts (issue 22): a path that
cannot be written fails at once with one ``error:`` line, not after the whole analysis."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Optional


def progress(total: int, unit: str, desc: str = ''):
    """A tqdm progress bar on stderr (``total`` ``unit``s), shown only when stdout and stderr
    are a terminal (a pipe or a log gets no bar characters)."""
    import sys

    from tqdm import tqdm

    on_terminal = sys.stdout.isatty() and sys.stderr.isatty()
    return tqdm(
        total=total, unit=unit, desc=desc or None, disable=not on_terminal, file=sys.stderr
    )


def check_output(path: Optional[str], option: str, directory: bool = False) -> None:
    """ValueError naming ``option`` unless ``path`` (a file, or a ``directory``) can be written.

    The missing parent folders are created (as the writers would); a file is probed by opening it
    for appending, and removed again if the probe created it.
    """
    if not path:
        return
    target = Path(path)
    folder = target if directory else target.parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
        if directory:
            probe = folder / f'.vib_estimator_probe_{os.getpid()}'
            probe.open('ab').close()
            probe.unlink()
        elif target.is_dir():
            raise IsADirectoryError(21, 'is a directory')
        else:
            existed = target.exists()
            target.open('ab').close()
            if not existed:
                target.unlink()
    except OSError as err:
        raise ValueError(f'{option} {path}: cannot write there ({err.strerror or err})') from None
