# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The library's exceptions, in one module, and what each means at a command line.

Every module of the package raises these (never defines its own), so a caller catches one family
and :func:`report` turns any of them into the one ``error:`` line and exit code the command-line
tools print and return. The node runner's ``StartupError`` (``nodes/runner.py``) is the node-side
counterpart and may move here.

Hierarchy::

    VibEstimatorError            -- anything this package refuses as input (exit 2)
    +-- CsvError                 -- a CSV file that cannot be read as asked
    +-- BagError                 -- a bag that cannot be read or written as asked
    |   +-- CorruptRecordError   -- a damaged record met with ``strict`` on
    +-- EmptyPlayback            -- nothing to play from the chosen start of a bag
    +-- McapFormatError          -- an MCAP file the indexed fast path cannot take (internal:
    |   +-- McapCut              --   the caller reads it another way); a record cut short
    +-- CdrLayoutError           -- payloads the vectorised CDR decoder cannot take (internal)
    +-- GeometryError            -- a geometry file (sensor layout) that cannot be read

``ValueError`` (a bad option value, e.g. an unknown component) also maps to exit code 2.
"""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path
from typing import Optional, TextIO

#: exit code of a command given input it refuses (one ``error:`` line on stderr)
EXIT_BAD_INPUT = 2


class VibEstimatorError(Exception):
    """Base of the package's exceptions: input refused, with one sentence saying why."""


class CsvError(VibEstimatorError):
    """A CSV file that cannot be read as asked; the message is one sentence naming the file."""


class BagError(VibEstimatorError):
    """A bag that cannot be read as asked; the message is one sentence naming the path."""


class CorruptRecordError(BagError):
    """A damaged record (MCAP chunk checksum, record framing, CDR payload) with ``strict`` on."""


class EmptyPlayback(VibEstimatorError):
    """Nothing to play from the chosen start of the bag."""


class McapFormatError(VibEstimatorError):
    """An MCAP file the indexed reader cannot take (no summary, chunks without indexes, ...)."""


class McapCut(McapFormatError):
    """An MCAP record runs past the end of its data; ``args``: where the cut record starts (if
    known), its opcode and the start of its body."""


class CdrLayoutError(VibEstimatorError):
    """A batch the vectorised decoder cannot take (not little-endian CDR, or too short)."""


class GeometryError(VibEstimatorError):
    """A geometry file (points, channels, lines: :mod:`vib_estimator.io.geometry`) that cannot be
    read or does not fit the record's channels; one sentence naming the file."""


class StartupError(VibEstimatorError):
    """A node's configuration it cannot start with (a parameter, a missing bag, a name rcl
    refuses): :func:`vib_estimator.nodes.runner.run` prints it as one ``error:`` line on stderr
    and exits with code 2, never a traceback."""


class DamageCount:
    """Mixin of a reader that skips damaged records: :meth:`count_damage` adds them to ``corrupt``
    and keeps the first description in ``damage`` -- or, with ``strict``, raises
    :class:`CorruptRecordError` naming ``path``."""

    path: Path
    strict: bool
    corrupt: int
    damage: str

    def count_damage(self, count: int, damage: str) -> None:
        """Count ``count`` damaged records (``damage`` says what); raise if ``strict``."""
        if count <= 0:
            return
        if self.strict:
            raise CorruptRecordError(f'{self.path}: {damage}')
        self.corrupt += count
        self.damage = self.damage or damage


#: exception class -> exit code of the command-line tools (the first match in order wins)
EXIT_CODES = ((VibEstimatorError, EXIT_BAD_INPUT), (ValueError, EXIT_BAD_INPUT))


def exit_code(err: BaseException) -> Optional[int]:
    """The exit code a command returns for ``err``; None for an exception that is a bug."""
    return next((code for cls, code in EXIT_CODES if isinstance(err, cls)), None)


def report(err: BaseException, prog: str = '', stream: Optional[TextIO] = None) -> int:
    """Print ``err`` as the one ``[prog: ]error: ...`` line on stderr; return its exit code."""
    prefix = f'{prog}: ' if prog else ''
    print(f'{prefix}error: {err}', file=stream or sys.stderr, flush=True)
    return exit_code(err) or EXIT_BAD_INPUT


@contextlib.contextmanager
def as_bag_error(path: Path, doing: str):
    """Turn any failure of a bag parser into one :class:`BagError` sentence.

    A corrupt or truncated file makes ``rosbags`` fail with whatever its parsing step raises
    (``ReaderError``, ``struct.error``, ``KeyError``, ``sqlite3.DatabaseError``, ...), so every
    exception is caught here, once, and reported with the path. For a bag directory the sentence
    names the repair: ``vib-estimator reindex`` (a recorder killed mid-file leaves such a bag).
    """
    try:
        yield
    except BagError:
        raise
    except Exception as err:  # noqa: BLE001 -- see docstring
        path = Path(path)
        detail = str(err).strip().rstrip('.') or type(err).__name__
        repair = (
            f'; `vib-estimator reindex {path}` rebuilds it from what is complete'
            if path.is_dir()
            else ''
        )
        raise BagError(
            f'cannot {doing} {path}: {detail} (corrupt or truncated bag?{repair})'
        ) from None
