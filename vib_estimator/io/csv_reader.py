"""Reading a signal from a CSV file (pure Python/numpy; no rclpy).

Format: optional ``#`` comment lines, an optional header row, then rows whose first column is the
time in seconds. The signal is a named column (header) or a column index; by default the second.
Empty cells and ``nan`` are kept as NaN (the estimator skips and counts them).

This module holds the rules (:func:`csv_layout` finds the header, the column and where the data
start; :func:`iter_csv_rows` is the exact row-by-row reading, with the error messages). The fast
path, block by block, is :mod:`.streaming`; :func:`read_csv_series` collects its blocks.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator, List, Optional, Tuple

import numpy as np


class CsvError(Exception):
    """A CSV file that cannot be read as asked; the message is one sentence naming the file."""


@dataclass(frozen=True)
class Series:
    """A sampled signal: time (s) and values, plus the name of the column read."""

    t: np.ndarray
    y: np.ndarray
    name: str


@dataclass(frozen=True)
class CsvLayout:
    """Where a CSV file's data are: the signal column, the header, the first data row's byte."""

    path: Path
    index: int
    name: str
    width: int
    has_header: bool
    data_offset: int


def _number(cell: str) -> float:
    cell = cell.strip()
    return float('nan') if cell == '' else float(cell)


def _rows(handle, first_line: int = 1) -> Iterator[Tuple[int, int, List[str]]]:
    """(line number, byte offset, cells) of the non-comment, non-empty rows of a binary file."""
    offset, line = handle.tell(), first_line
    for raw in iter(handle.readline, b''):
        text = raw.decode()
        row = next(csv.reader([text]), [])
        if row and not row[0].lstrip().startswith('#'):
            yield line, offset, row
        offset += len(raw)
        line += 1


def csv_layout(path, column: Optional[str] = None) -> CsvLayout:
    """The layout of a CSV file; ``column`` a header name or a 0-based index (as text), None = the
    second column. Raises :class:`CsvError` for a missing file, an unknown column or no data."""
    path = Path(path)
    if not path.is_file():
        raise CsvError(f'no such file: {path}')
    try:
        with path.open('rb') as handle:
            rows = _rows(handle)
            first = next(rows, None)
            if first is None:
                raise CsvError(f'{path} has no data rows')
            header = None
            try:
                _number(first[2][0])
                data = first
            except ValueError:
                header = [name.strip() for name in first[2]]
                data = next(rows, None)
                if data is None:
                    raise CsvError(f'{path} has a header but no data rows') from None
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise CsvError(f'cannot read {path} as CSV: {err}') from None
    width = len(data[2])
    names = header or [str(i) for i in range(width)]
    index = _column_index(path, column, names, width)
    return CsvLayout(path, index, names[index], width, header is not None, data[1])


def _column_index(path: Path, column: Optional[str], names: List[str], width: int) -> int:
    if column is None:
        if width < 2:
            raise CsvError(f'{path} has one column; need time and a signal column')
        index = 1
    elif column in names:
        index = names.index(column)
    elif column.isdigit() and int(column) < width:
        index = int(column)
    else:
        raise CsvError(f'{path} has no column {column!r}; columns are {", ".join(names)}')
    if index == 0:
        raise CsvError(f'column {column!r} of {path} is the time column')
    return index


def iter_csv_rows(layout: CsvLayout) -> Iterator[Tuple[float, float]]:
    """(t, value) of every data row, by the exact rules; CsvError names a row that is not
    numbers (by its data-row number, counting the header as row 1)."""
    try:
        with layout.path.open('rb') as handle:
            handle.seek(layout.data_offset)
            for count, (_, _, row) in enumerate(_rows(handle)):
                try:
                    yield _number(row[0]), _number(row[layout.index])
                except (ValueError, IndexError):
                    line = count + 2 if layout.has_header else count + 1
                    raise CsvError(f'{layout.path}: data row {line} is not numbers in columns 0 '
                                   f'and {layout.index}: {",".join(row)!r}') from None
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise CsvError(f'cannot read {layout.path} as CSV: {err}') from None


def read_csv_series(path, column: Optional[str] = None) -> Series:
    """Read time (first column) and the signal column of a CSV file, all at once.

    ``column`` is a header name or a 0-based column index (as text); None = the second column.
    Raises :class:`CsvError` for a missing file, an unknown column, a cell that is not a number,
    or a file with no data rows.
    """
    from .streaming import csv_signal

    signal = csv_signal(Path(path), column)
    parts = list(signal.blocks()) or [(np.empty(0), np.empty(0))]
    t, y = (np.concatenate(p) for p in zip(*parts))
    return Series(t, y, signal.label)
