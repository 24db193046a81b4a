# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Reading a signal from a CSV file (pure Python/numpy; no rclpy).

Format: optional ``#`` comment lines, an optional header row, then rows whose first column is the
time in seconds -- or in milliseconds, microseconds or nanoseconds where the time column's name
says so (``time_ms``, ``t [us]``, ``stamp_ns``: :func:`time_unit`), or a row of units under the
header (``(ms),(V)``) does. The signal is a named column
(header) or a column index; by default the second. The cells are separated by commas, or by
semicolons or tabs where the first row has them (a decimal comma then read too: ``0,25;1,5``),
or by spaces where it has none of these (``.asc``/``.dat`` exports): :func:`sniff`. What pandas'
``to_csv`` writes reads as meant: an unnamed row index before the time is left out, a time
column of ISO 8601 dates is read as seconds since its first, and a time column named as one is
read as the time wherever it stands (:attr:`CsvLayout.order`, :attr:`CsvLayout.origin`; said by
:func:`time_words`).
Without a header row, the last comment line before the data names the columns when it lists one
name per column (``# time_s,accel_g  (notes)``: names separated by commas, up to two spaces or a
parenthesis; :func:`comment_names`).
Empty cells and ``nan`` are kept as NaN (the estimator skips and counts them).
A logger's file without a time column is read too: a header row of settings that names the sample
rate (``sample_rate``, ``sampling_rate``, ``fs``, ``rate``, optionally ``_hz``), the row of their
values, then one sample per row (:func:`rate_layout`): the time is the row's index over the rate,
and the layout shows it as a time column 0 named ``t`` and the samples as column 1, ``signal``.

This module holds the rules (:func:`csv_layout` finds the header, the column and where the data
start; :func:`iter_csv_rows` is the exact row-by-row reading, with the error messages) and the fast
path, block by block (:func:`csv_blocks`: ``pyarrow.csv``'s streaming reader; a file it refuses --
comment lines between the data, cells with spaces, ragged rows, a cell that is not a number -- is
read by the exact rules instead, so the result and the error messages are those of the rules).
:func:`read_csv_series` collects the blocks; :mod:`.streaming` streams them.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass, replace
from datetime import datetime
from pathlib import Path
from typing import Iterator, List, Optional, Tuple

import numpy as np

from ..errors import CsvError
from ..extras import optional

#: bytes of CSV text per parsed block (512 kB: ~20 k rows). Arrow's streaming reader reads up to
#: 32 blocks ahead on its I/O thread, so this sets the reader's memory (~16 MB in flight; 2 MB
#: blocks held ~70 MB) while larger blocks parse no faster per CPU second
#: (benchmarks/bench_survey.py)
CSV_BLOCK_BYTES = 1 << 19
#: rows per block of the exact (row-by-row) path when no block size is given
EXACT_BLOCK_ROWS = 1 << 18
#: how a file without a time column is read (:func:`rate_layout`), said where one is missing
NO_TIME = (
    'the first column is the time; a file without one: a first row sample_rate_hz, the rate in '
    'the second, then one sample a row'
)
#: the suffixes of the text tables read as CSV (commas, semicolons, tabs or spaces between cells)
CSV_SUFFIXES = ('.csv', '.txt', '.tsv', '.dat', '.asc')


@dataclass(frozen=True)
class Series:
    """A sampled signal: time (s) and values, plus the name of the column read."""

    t: np.ndarray
    y: np.ndarray
    name: str


@dataclass(frozen=True)
class CsvLayout:
    """Where a CSV file's data are: the signal column, the header, the first data row's byte;
    ``indices``: every signal column read (one pass of :func:`csv_column_blocks`), ``index``
    first."""

    path: Path
    index: int
    name: str
    width: int
    has_header: bool
    data_offset: int
    indices: Tuple[int, ...] = ()
    #: every column's name: the header's, a comment line's (:func:`comment_names`) or its index
    names: Tuple[str, ...] = ()
    #: samples per second of a file without a time column (:func:`rate_layout`; 0: column 0 is
    #: the time): its columns are then the layout's columns 1 on
    rate: float = 0.0
    #: the cells' separator (None: runs of whitespace) and decimal mark (:func:`sniff`)
    delimiter: Optional[str] = ','
    decimal: str = '.'
    #: seconds per unit of the time column (:func:`time_unit`)
    time_scale: float = 1.0
    #: the file's column of each of the layout's (the time first), where not the same column
    #: (): a row index without a name left out (pandas' ``to_csv``), a time column not first
    order: Tuple[int, ...] = ()
    #: the file's columns (``width`` and those left out)
    file_width: int = 0
    #: the first row's time, when the times are dates (ISO 8601): they are read as seconds since
    origin: Optional[datetime] = None
    #: the row of units under the header, if the file has one (each column's, time first)
    units: Tuple[str, ...] = ()

    @property
    def dialect(self) -> Tuple[Optional[str], str]:
        return self.delimiter, self.decimal

    def cell(self, index: int) -> int:
        """The file's column of the layout's column ``index``."""
        if self.order:
            return self.order[index]
        return index - 1 if self.rate else index

    def seconds(self, cell: str) -> float:
        """The time of a row whose time cell is ``cell`` (ValueError if it is none)."""
        if self.origin is None:
            return _number(cell) * self.time_scale
        date = _date(cell)
        try:
            return (date - self.origin).total_seconds()
        except TypeError:  # no date, or a zone where the first had none (or none where it had)
            raise ValueError(cell) from None

    @property
    def columns(self) -> Tuple[int, ...]:
        return self.indices or (self.index,)


def _number(cell: str) -> float:
    cell = cell.strip()
    return float('nan') if cell == '' else float(cell)


def _date(cell: str) -> Optional[datetime]:
    """The date and time of an ISO 8601 cell (``2024-08-12 21:08:55.125``, a ``T``, a zone),
    None for any other text (a number among them)."""
    text = cell.strip()
    if len(text) < 8 or not ('-' in text[1:] or ':' in text):
        return None
    try:
        return datetime.fromisoformat(text[:-1] + '+00:00' if text.endswith('Z') else text)
    except ValueError:
        return None


def _rows(
    handle, dialect: Tuple[Optional[str], str] = (',', '.'), first_line: int = 1
) -> Iterator[Tuple[int, int, List[str]]]:
    """(line number, byte offset, cells) of the non-comment, non-empty rows of a binary file,
    split by ``dialect`` (:func:`sniff`: a decimal comma's cells given a decimal point)."""
    delimiter, decimal = dialect
    offset, line = handle.tell(), first_line
    for raw in iter(handle.readline, b''):
        text = raw.decode()
        if offset == 0:  # a spreadsheet's byte-order mark (Excel's "CSV UTF-8") is no cell
            text = text.lstrip(BOM)
        if delimiter is None:
            row = text.split()
        else:
            row = next(csv.reader([text], delimiter=delimiter), [])
        if row and not row[0].lstrip().startswith('#'):
            yield line, offset, [cell.replace(',', '.') for cell in row] if decimal == ',' else row
        offset += len(raw)
        line += 1


#: the byte-order mark a spreadsheet may write first (not part of the first cell)
BOM = '\ufeff'
#: the rows :func:`sniff` reads
SNIFF_ROWS = 20
#: a number written with a decimal comma (``-0,25``, ``1,5e-3``)
_DECIMAL_COMMA = re.compile(r'[+-]?\d*,\d+(?:[eE][+-]?\d+)?')


def sniff(path: Path) -> Tuple[Optional[str], str]:
    """``(delimiter, decimal mark)`` of a CSV file from its first :data:`SNIFF_ROWS` rows that are
    not comments: a semicolon, a tab or a comma, the first of them the first row has (or, a header
    of one name, the second), else runs of whitespace (None); a decimal comma where a semicolon or
    a tab separates the cells and one of these rows has a cell written so."""
    rows = []
    with path.open('rb') as handle:
        for raw in handle:
            text = raw.decode().strip().lstrip(BOM)
            if text and not text.startswith('#'):
                rows.append(text)
                if len(rows) == SNIFF_ROWS:
                    break
    for row in rows[:2]:
        for delimiter in (';', '\t', ','):
            if delimiter in row:
                comma = delimiter != ',' and any(
                    _DECIMAL_COMMA.fullmatch(cell.strip())
                    for other in rows
                    for cell in other.split(delimiter)
                )
                return delimiter, ',' if comma else '.'
        if len(row.split()) > 1:
            break
    return (None if any(len(row.split()) > 1 for row in rows[:2]) else ','), '.'


#: a time column's unit in its name (after a separator, or alone): seconds per unit
TIME_UNITS = {
    'ms': 1e-3,
    'msec': 1e-3,
    'millis': 1e-3,
    'milliseconds': 1e-3,
    'us': 1e-6,
    'usec': 1e-6,
    'micros': 1e-6,
    'microseconds': 1e-6,
    'ns': 1e-9,
    'nsec': 1e-9,
    'nanos': 1e-9,
    'nanoseconds': 1e-9,
}
_TIME_UNIT = re.compile(r'(?:.*[\s_\-.\[(/])?([a-z]+)[\])]?', re.IGNORECASE)


def time_words(layout: CsvLayout) -> str:
    """How the time was read, when not as seconds in the first column: a row index left out, a
    unit the time column's name gives (:func:`time_unit`), dates; '' otherwise."""
    if layout.rate:
        return ''
    name = layout.names[0] if layout.names else ''
    time, left_out = layout.cell(0), layout.file_width - layout.width if layout.order else 0
    words = []
    if left_out:
        words.append('the first column (no name, 0 in the first row) read as a row index')
    if time != left_out:
        words.append(f'column {time} ({name}) read as the time, by its name')
    if layout.origin is not None:
        words.append(
            f'time column {name or time} read as dates, in seconds since the first '
            f'({layout.origin.isoformat(" ")})'
        )
    elif layout.time_scale != 1.0:
        named = time_unit(name)[1] != 1.0
        unit = time_unit(name if named else layout.units[0])[0]
        says = 'its name says so' if named else 'the row of units says so'
        words.append(f'time column {name} read in {unit} ({layout.time_scale:g} s each: {says})')
    if layout.units:
        words.append('the row under the names read as units: ' + ', '.join(layout.units))
    return '; '.join(words)


def time_unit(name: str) -> Tuple[str, float]:
    """``(unit, seconds per unit)`` of a time column named ``name``: ``time_ms``, ``t [ms]``,
    ``Time (us)``, ``stamp_ns``, ``ms`` are read in milliseconds, microseconds, nanoseconds;
    any other name in seconds (``('s', 1.0)``)."""
    match = _TIME_UNIT.fullmatch(name.strip())
    unit = match.group(1).lower() if match else ''
    return (unit, TIME_UNITS[unit]) if unit in TIME_UNITS else ('s', 1.0)


def csv_layout(path, column: Optional[str] = None) -> CsvLayout:
    """The layout of a CSV file; ``column`` a header name or a 0-based index (as text), None = the
    second column. Raises :class:`CsvError` for a missing file, an unknown column or no data."""
    path = Path(path)
    if not path.is_file():
        raise CsvError(f'no such file: {path}')
    try:
        dialect = sniff(path)
        with path.open('rb') as handle:
            rows = _rows(handle, dialect)
            first = next(rows, None)
            if first is None:
                raise CsvError(f'{path} has no data rows')
            header, data, units = None, first, ()
            if _is_header(first[2]):
                header = [name.strip() for name in first[2]]
                data = next(rows, None)
                if data is not None and _is_units(data[2]):  # a row of units under the names
                    units, data = tuple(cell.strip() for cell in data[2]), next(rows, None)
                if data is None:
                    raise CsvError(f'{path} has a header but no data rows') from None
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise CsvError(f'cannot read {path} as CSV: {err}') from None
    width = len(data[2])
    if header is not None:
        timed = rate_layout(path, header, data, column, dialect)
        if timed is not None:
            return timed
        header += [str(i) for i in range(len(header), width)]  # (a cell the header leaves out)
    names = header or comment_names(path, data[1], width) or [str(i) for i in range(width)]
    order = _time_first(names, data[2])
    names = [names[i] for i in order]
    units = tuple((units + ('',) * width)[i] for i in order) if units else ()
    index = _column_index(path, column, names, len(order))
    unit = time_unit(names[0])
    if unit[1] == 1.0 and units:
        unit = time_unit(units[0])
    return CsvLayout(
        path,
        index,
        names[index],
        len(order),
        header is not None,
        data[1],
        names=tuple(names),
        delimiter=dialect[0],
        decimal=dialect[1],
        time_scale=unit[1],
        order=() if order == list(range(width)) else tuple(order),
        file_width=width,
        origin=_date(data[2][order[0]]),
        units=units,
    )


#: a cell of a row of units under a header: ``(ms)``, ``[m/s^2]``, ``V``, ``deg``, ``%`` ...
_UNIT = re.compile(r'[(\[]?\s*[A-Za-zµ°%][\w/^*.·°µ%\s-]{0,11}\s*[)\]]?')


def _is_units(cells: List[str]) -> bool:
    """Whether a row under the header is its columns' units (an oscilloscope's export: ``Time,
    Channel A`` then ``(ms),(V)``): every cell empty or a short unit, one at least."""
    texts = [cell.strip() for cell in cells]
    return any(texts) and all(not t or (_UNIT.fullmatch(t) and not _is_number(t)) for t in texts)


def _is_header(cells: List[str]) -> bool:
    """Whether a first row is a header: its first cell neither a number nor a date, or empty
    (a row index without a name: pandas' ``to_csv``) beside a cell that is no number."""
    head = cells[0].strip()
    if head == '':
        return any(_date(c) is None and not _is_number(c) for c in cells[1:])
    return not _is_number(head) and _date(head) is None


def _is_number(cell: str) -> bool:
    try:
        _number(cell)
    except ValueError:
        return False
    return True


#: a time column's name: ``t``, ``time``, ``timestamp``, ``stamp``, ``elapsed``, ``seconds``,
#: ``millis`` ..., alone or with a unit or note after a separator (``Time (s)``, ``time_ms``)
_TIME_NAME = re.compile(
    r'(t|time|timestamp|stamp|elapsed|seconds|secs?|millis|micros|zeit)([\s_\-\[(/.].*)?',
    re.IGNORECASE,
)


def _time_first(names: List[str], cells: List[str]) -> List[int]:
    """The file's columns in the layout's order, the time first: a row index (pandas' ``to_csv``
    with its default index: no name, 0 in the first row, before a time and a signal) left out;
    the one column whose name is a time's (:data:`_TIME_NAME`) first, where the first column's
    is not (a logger's ``ax,ay,az,millis``)."""
    order = list(range(len(names)))
    if len(names) >= 3 and names[0] == '' and cells[0].strip() == '0':
        order = order[1:]
    timed = [i for i in order if _TIME_NAME.fullmatch(names[i].strip())]
    if len(timed) == 1 and timed[0] != order[0] and not _TIME_NAME.fullmatch(names[order[0]]):
        order.remove(timed[0])
        order.insert(0, timed[0])
    return order


#: a header cell that names the sample rate (:func:`rate_layout`)
_RATE = re.compile(r'(sample_?rate|sampling_?rate|fs|rate)(_?hz)?', re.IGNORECASE)
#: the names :func:`rate_layout` gives the time and the samples
RATE_NAMES = ('t', 'signal')


def rate_layout(
    path: Path, header: List[str], settings, column: Optional[str], dialect=(',', '.')
):
    """The layout of a file without a time column (module doc), or None when ``header`` (the
    first row) and ``settings`` (the next: line, offset, cells) are not a header of settings
    naming the sample rate followed by one sample per row."""
    keys = [i for i, name in enumerate(header) if _RATE.fullmatch(name)]
    if len(keys) != 1 or len(settings[2]) != len(header):
        return None
    try:
        rate = _number(settings[2][keys[0]])
        with path.open('rb') as handle:
            handle.seek(settings[1])
            handle.readline()
            sample = next(_rows(handle, dialect), None)
        if sample is None or len(sample[2]) != 1:
            return None
        _number(sample[2][0])
    except (ValueError, OSError, UnicodeDecodeError, csv.Error):
        return None
    if not (math.isfinite(rate) and rate > 0):
        raise CsvError(f'{path}: the sample rate {header[keys[0]]} = {rate:g} is not positive')
    index = _column_index(path, column, list(RATE_NAMES), 2)
    return CsvLayout(
        path,
        index,
        RATE_NAMES[index],
        2,
        True,
        sample[1],
        names=RATE_NAMES,
        rate=rate,
        delimiter=dialect[0],
        decimal=dialect[1],
    )


#: a column name in a comment header: a letter or underscore, then word characters and . - / [ ]
_NAME = re.compile(r'[A-Za-z_][\w.\-/\[\]]*')


def comment_names(path: Path, data_offset: int, width: int) -> Optional[List[str]]:
    """The column names of the last ``#`` comment line before the data (at byte
    ``data_offset``), when it lists ``width`` distinct names separated by commas (text after two
    spaces or a parenthesis is a note); None otherwise."""
    with path.open('rb') as handle:
        head = handle.read(data_offset).decode(errors='replace').lstrip(BOM).splitlines()
    comments = [line.strip() for line in head if line.strip().startswith('#')]
    if not comments:
        return None
    text = re.split(r'\s{2,}|\s*\(', comments[-1].lstrip('#').strip())[0]
    cells = [cell.strip() for cell in text.split(',')]
    if len(cells) != width or len(set(cells)) != width:
        return None
    return cells if all(_NAME.fullmatch(cell) for cell in cells) else None


def _column_index(path: Path, column: Optional[str], names: List[str], width: int) -> int:
    if column is None:
        if width < 2:
            raise CsvError(f'{path} has one column; need time and a signal column ({NO_TIME})')
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
    for t, values in iter_csv_column_rows(layout):
        yield t, values[0]


def iter_csv_column_rows(layout: CsvLayout) -> Iterator[Tuple[float, List[float]]]:
    """(t, [value of each of ``layout.columns``]) of every data row, by the exact rules."""
    columns = [layout.cell(i) for i in layout.columns]
    rate = layout.rate
    try:
        with layout.path.open('rb') as handle:
            handle.seek(layout.data_offset)
            for count, (_, _, row) in enumerate(_rows(handle, layout.dialect)):
                try:
                    t = count / rate if rate else layout.seconds(row[layout.cell(0)])
                    yield t, [_number(row[i]) for i in columns]
                except (ValueError, IndexError):
                    line = count + (3 if rate else 2 if layout.has_header else 1)
                    line += 1 if layout.units else 0
                    raise CsvError(
                        f'{layout.path}: data row {line} is not numbers in columns 0 '
                        f'and {", ".join(map(str, columns))}: {",".join(row)!r}'
                    ) from None
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise CsvError(f'cannot read {layout.path} as CSV: {err}') from None


def csv_blocks(
    layout: CsvLayout, block_rows: int = EXACT_BLOCK_ROWS
) -> Iterator[Tuple[np.ndarray, np.ndarray]]:
    """``(t, y)`` blocks of the file's signal column (:func:`csv_column_blocks`)."""
    for t, y in csv_column_blocks(layout, block_rows):
        yield t, y[:, 0]


def csv_column_blocks(
    layout: CsvLayout, block_rows: int = EXACT_BLOCK_ROWS
) -> Iterator[Tuple[np.ndarray, np.ndarray]]:
    """``(t, Y)`` blocks of the file, ``Y[:, k]`` its ``layout.columns[k]``, by pyarrow; on a file
    it refuses, the rest by the exact rules (``block_rows`` rows per block); all of it by the exact
    rules where pyarrow is missing or does not load (:func:`..extras.optional`)."""
    pa, pacsv = optional('pyarrow'), optional('pyarrow.csv')
    exact = layout.delimiter is None or layout.decimal != '.' or layout.origin is not None
    if pa is None or pacsv is None or exact:  # (or spaces, a decimal comma, dates)
        yield from _exact_blocks(layout, 0, block_rows)
        return

    rate = layout.rate
    names = [f'c{i}' for i in range(layout.file_width or layout.width - (1 if rate else 0))]
    time = names[layout.cell(0)] if not rate else ''
    wanted = ([] if rate else [time]) + [names[layout.cell(i)] for i in layout.columns]
    done = 0
    try:
        # read by arrow itself, not through a Python file: a Python read allocates a fresh 2 MB
        # bytes object per block, which a process tuned to return memory at once (Dask's nanny
        # sets MALLOC_TRIM_THRESHOLD_) maps and unmaps every time (4x the page faults)
        with pa.OSFile(str(layout.path)) as handle:
            handle.seek(layout.data_offset)
            reader = pacsv.open_csv(
                handle,
                memory_pool=pa.system_memory_pool(),
                read_options=pacsv.ReadOptions(
                    column_names=names, use_threads=False, block_size=CSV_BLOCK_BYTES
                ),
                parse_options=pacsv.ParseOptions(
                    delimiter=layout.delimiter, newlines_in_values=False
                ),
                convert_options=pacsv.ConvertOptions(
                    column_types={n: pa.float64() for n in wanted},
                    include_columns=wanted,
                    null_values=[''],
                    strings_can_be_null=False,
                    quoted_strings_can_be_null=True,
                ),
            )
            for batch in reader:
                if rate:
                    t = (done + np.arange(batch.num_rows)) / rate
                else:
                    t = np.asarray(batch.column(time).to_numpy(zero_copy_only=False), np.float64)
                    if layout.time_scale != 1.0:
                        t = t * layout.time_scale
                y = np.empty((len(t), len(layout.columns)))
                for k, i in enumerate(layout.columns):
                    y[:, k] = batch.column(names[layout.cell(i)]).to_numpy(zero_copy_only=False)
                done += len(t)
                yield t, y
    except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError):
        yield from _exact_blocks(layout, done, block_rows)


def _exact_blocks(
    layout: CsvLayout, skip: int, block_rows: int
) -> Iterator[Tuple[np.ndarray, np.ndarray]]:
    """The exact rules, block by block, after the first ``skip`` data rows: ``(t, Y)``."""
    width = len(layout.columns)
    t: List[float] = []
    y: List[List[float]] = []
    for i, (ti, yi) in enumerate(iter_csv_column_rows(layout)):
        if i < skip:
            continue
        t.append(ti)
        y.append(yi)
        if len(t) == block_rows:
            yield np.array(t), np.array(y).reshape(-1, width)
            t, y = [], []
    if t:
        yield np.array(t), np.array(y).reshape(-1, width)


def read_csv_series(path, column: Optional[str] = None) -> Series:
    """Read time (first column) and the signal column of a CSV file, all at once.

    ``column`` is a header name or a 0-based column index (as text); None = the second column.
    Raises :class:`CsvError` for a missing file, an unknown column, a cell that is not a number,
    or a file with no data rows.
    """
    layout = csv_layout(path, column)
    parts = list(csv_blocks(layout)) or [(np.empty(0), np.empty(0))]
    t, y = (np.concatenate(p) for p in zip(*parts))
    return Series(t, y, layout.name)


def column_names(path, columns: str) -> List[str]:
    """The signal columns of ``--columns``: ``all`` (every column but the time) or a
    comma-separated list of header names or 0-based indices (as text). Raises :class:`CsvError`
    for an unknown or repeated column."""
    layout = csv_layout(path)
    names = list(layout.names)
    if columns.strip() == 'all':
        return names[1:]
    out = []
    for item in (c.strip() for c in columns.split(',')):
        name = names[_column_index(layout.path, item, names, layout.width)]
        if name in out:
            raise CsvError(f'column {item!r} of {layout.path} is given twice')
        out.append(name)
    return out


def read_csv_columns(path, columns: str) -> Tuple[np.ndarray, np.ndarray, List[str]]:
    """``(t, Y, names)``: time and the ``columns`` (:func:`column_names`) as the columns of
    ``Y``, read in one pass by :func:`read_csv_series`'s rules."""
    names = column_names(path, columns)
    layout = csv_layout(path, names[0])
    every = list(layout.names)
    layout = replace(layout, indices=tuple(every.index(name) for name in names))
    parts = list(csv_column_blocks(layout)) or [(np.empty(0), np.empty((0, len(names))))]
    t, y = (np.concatenate(p) for p in zip(*parts))
    return t, y, names
