"""Reading a signal from a CSV file (pure Python/numpy; no rclpy).

Format: optional ``#`` comment lines, an optional header row, then rows whose first column is the
time in seconds. The signal is a named column (header) or a column index; by default the second.
Empty cells and ``nan`` are kept as NaN (the estimator skips and counts them).
"""
from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path
from typing import List, Optional

import numpy as np


class CsvError(Exception):
    """A CSV file that cannot be read as asked; the message is one sentence naming the file."""


@dataclass(frozen=True)
class Series:
    """A sampled signal: time (s) and values, plus the name of the column read."""

    t: np.ndarray
    y: np.ndarray
    name: str


def _number(cell: str) -> float:
    cell = cell.strip()
    return float('nan') if cell == '' else float(cell)


def read_csv_series(path, column: Optional[str] = None) -> Series:
    """Read time (first column) and the signal column of a CSV file.

    ``column`` is a header name or a 0-based column index (as text); None = the second column.
    Raises :class:`CsvError` for a missing file, an unknown column, a cell that is not a number,
    or a file with no data rows.
    """
    path = Path(path)
    if not path.is_file():
        raise CsvError(f'no such file: {path}')
    try:
        with path.open(newline='') as handle:
            rows: List[List[str]] = [row for row in csv.reader(handle)
                                     if row and not row[0].lstrip().startswith('#')]
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise CsvError(f'cannot read {path} as CSV: {err}') from None
    if not rows:
        raise CsvError(f'{path} has no data rows')
    header = None
    try:
        _number(rows[0][0])
    except ValueError:
        header = [name.strip() for name in rows[0]]
        rows = rows[1:]
    if not rows:
        raise CsvError(f'{path} has a header but no data rows')
    width = len(rows[0])
    names = header or [str(i) for i in range(width)]
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
    t = np.empty(len(rows))
    y = np.empty(len(rows))
    for i, row in enumerate(rows):
        try:
            t[i] = _number(row[0])
            y[i] = _number(row[index])
        except (ValueError, IndexError):
            line = i + 2 if header else i + 1
            raise CsvError(f'{path}: data row {line} is not numbers in columns 0 and {index}: '
                           f'{",".join(row)!r}') from None
    return Series(t, y, names[index])
