# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``analyze --columns a,b,c|all`` (CSV), ``analyze BAG --components a,b,c`` (several fields
of one bag topic) and ``analyze BAG --topics /a,/b,/c`` (the ``--component`` or
``--components`` of several topics, their samples aligned by header stamp as the node's
``input_topics``: :mod:`..io.align`; channels ``topic:field``): several channels, one set of
modes with their shapes.

One column (``--columns b``) is exactly ``--column b``, one component exactly ``--component``.
Two or more go to the joint estimator of the excitation (:func:`..core.create_estimator`: free
decays or ``--excitation ambient``; ``auto`` takes one channel). Each estimate row (JSONL, CSV,
table) gains, per channel ``<name>``: ``shape_<name>`` (the signed amplitude,
:func:`..core.shapes.signed_amplitudes`), ``shape_phase_deg_<name>`` (its phase, degrees, 0 or
180 for a real mode), ``shape_std_<name>`` (its uncertainty) and ``mac`` (with the same
mode's previous estimate; null at its first); a bag's rows also ``stamp_ns``, as
``--component``'s. ``--plot``: the estimates over time by mode and each mode's shape as a bar
plot of the channel amplitudes (median over the mode's estimates).
"""

from __future__ import annotations

import sys

import numpy as np

from ..core import EstimatorConfig, create_estimator
from ..core.estimator import JointEstimates
from ..core.factory import kind_of
from ..core.shapes import SHAPE_ROWS, phases_deg, signed_amplitudes
from ..errors import BagError, CsvError
from ..io.csv_reader import NO_TIME, column_names, read_csv_columns
from ..io.fields import UNKNOWN_UNIT, seconds_since, signal_unit
from ..io.streaming import is_csv, open_signal, read_topics
from .choosing import explain_no_estimate, peaks_without_mode, prepare
from .summary import renumber, summarise_modes, summary_lines


def channel_names(args) -> list[str]:
    """The ``--columns`` of the CSV input (CsvError for a bag, with ``--column`` too, or for an
    unknown column)."""
    if not is_csv(args.input):
        raise CsvError('--columns reads CSV files only (a bag: --components)')
    if args.column is not None:
        raise CsvError('give --column or --columns, not both')
    return column_names(args.input, args.columns)


def component_names(args) -> list[str]:
    """The ``--components`` of the bag input (BagError for a CSV file or with ``--component``
    too; the fields are checked against the topic's type when the bag is opened)."""
    if is_csv(args.input):
        raise BagError('--components reads bags only (a CSV file: --columns)')
    if args.component is not None:
        raise BagError('give --component or --components, not both')
    try:
        return list(channel_list('--components', args.components))
    except ValueError as err:
        raise BagError(str(err)) from None


def channel_list(option: str, text: str) -> tuple[str, ...]:
    """The comma-separated names of ``option`` (ValueError for an empty or repeated one)."""
    names = tuple(n.strip() for n in text.split(','))
    if not all(names):
        raise ValueError(f'{option} {text!r} has an empty field')
    if len(set(names)) < len(names):
        raise ValueError(f'{option} {text!r} names a channel twice')
    return names


def need_joint(what: str, config: EstimatorConfig) -> None:
    """ValueError unless ``config`` has a joint estimator: ``what`` (several channels) needs one
    (:func:`..core.factory.kind_of`)."""
    kind_of(config, 2, what, '--excitation')


def read_channels(path, topic, names, strict: bool = False, info=None):
    """``(t, Y, names, signal)``: the channels ``names`` of the recording ``path`` (CSV
    columns: ``signal`` None; the fields of a bag's ``topic``: its
    :class:`..io.streaming.Signal`, read whole; ``info``: the bag's metadata, if read)."""
    if is_csv(path):
        t, y, names = read_csv_columns(path, ','.join(names))
        return t, y, names, None
    signal = open_signal(path, topic, strict=strict, components=names, info=info)
    blocks = [(t, y) for t, y in signal.blocks() if len(t)]
    if not blocks:
        raise ValueError(f'topic {signal.topic} of {signal.path} has no messages')
    t, y = (np.concatenate(part) for part in zip(*blocks))
    return t, y, list(signal.components), signal


def topic_list(args) -> tuple[str, ...]:
    """The ``--topics`` of the bag input (BagError for a CSV file, with ``--topic`` too, or an
    empty or repeated name)."""
    if is_csv(args.input):
        raise BagError('--topics reads bags only')
    if args.topic is not None:
        raise BagError('give --topic or --topics, not both')
    try:
        return channel_list('--topics', args.topics)
    except ValueError as err:
        raise BagError(str(err)) from None


def read_joint(args, names):
    """``(t, Y, channel names, the bags' signals (none for CSV), the first stamp in ns, the
    alignment's counters)`` of ``analyze``'s several channels: CSV ``--columns``, a bag topic's
    ``--components`` or the fields of several ``--topics`` aligned by stamp
    (:func:`..io.streaming.read_topics`)."""
    strict = getattr(args, 'strict', False)
    topics = getattr(args, 'topics_list', ())
    if len(topics) < 2:
        t, y, names, signal = read_channels(args.input, args.topic, names, strict)
        if signal is None:
            return t, y, names, (), 0, {}
        return t, y, names, (signal,), signal.origin_ns, {}
    aligned = read_topics(
        args.input,
        topics,
        args.component,
        names or None,
        round(args.sync_tolerance_s * 1e9),
        strict,
    )
    if not len(aligned.stamps):
        raise ValueError(f'the topics {", ".join(topics)} of {args.input} have no joint sample')
    origin = int(aligned.stamps[0])
    t = seconds_since(aligned.stamps, origin)
    return t, aligned.values, list(aligned.channels), aligned.signals, origin, aligned.counters


def joint_run(t: np.ndarray, y: np.ndarray, names, config: EstimatorConfig):
    """``(estimator, estimates)``: the joint identification of the channels (ValueError
    with ``excitation`` auto, for time not strictly increasing)."""
    need_joint(f'{len(names)} channels', config)
    bad = np.flatnonzero(~(np.diff(t) > 0))
    if bad.size:
        raise ValueError(
            f'time is not strictly increasing at sample {int(bad[0]) + 1} '
            f'(in a CSV file: {NO_TIME})'
        )
    estimator = create_estimator(config, names)
    return estimator, estimator.process(t, y)


def shape_fields(result: JointEstimates, i: int) -> dict:
    """The shape fields of estimate ``i`` (see the module doc)."""
    shape = result.shapes[i]
    parts = (signed_amplitudes(shape), phases_deg(shape), result.shape_std[i])
    row = {
        f'{field}_{name}': float(value)
        for field, values in zip(SHAPE_ROWS, parts)
        for name, value in zip(result.channels, values)
    }
    row['mac'] = float(result.mac[i])
    return row


def rows(result: JointEstimates) -> list[dict]:
    """One dict per estimate: the estimate's fields and its shape's."""
    return [
        {**e.as_dict(), **shape_fields(result, i)}
        for i, e in enumerate(result.estimates.to_list())
    ]


def print_rows(table: list[dict], fmt: str, json_row) -> None:
    out = sys.stdout
    if fmt == 'jsonl':
        import json

        for row in table:
            out.write(json.dumps(json_row(row), allow_nan=False) + '\n')
        return
    if fmt == 'csv':
        keys = list(table[0]) if table else ['t', 'mode', 'frequency_hz']
        out.write(','.join(keys) + '\n')
        for row in table:
            out.write(','.join(repr(row[k]) for k in keys) + '\n')
        return
    names = [k[len('shape_') :] for k in (table[0] if table else {}) if k.startswith('shape_')]
    names = [n for n in names if not n.startswith(('phase_deg_', 'std_'))]
    out.write(
        f'{"t (s)":>10} {"mode":>4} {"f (Hz)":>10} {"f std":>8} {"zeta":>8} {"MAC":>6}  shape '
        + ' '.join(names)
        + '\n'
    )
    for row in table:
        shape = ' '.join(f'{row["shape_" + n]:+.3f}' for n in names)
        out.write(
            f'{row["t"]:10.3f} {row["mode"]:4d} {row["frequency_hz"]:10.5f} '
            f'{row["frequency_std_hz"]:8.2g} {row["damping"]:8.5f} {row["mac"]:6.3f}  {shape}\n'
        )


def mode_shapes(
    result: JointEstimates, mode=None
) -> dict[int, tuple[float, np.ndarray, np.ndarray]]:
    """Per mode number: (median frequency, median signed shape amplitude per channel, median
    shape std per channel); ``mode``: each estimate's mode (None: the number it carries; the
    summary's, by identity: :func:`.summary.renumber`)."""
    e = result.estimates
    mode = e.mode if mode is None else mode
    signed = np.abs(result.shapes) * np.sign(result.shapes.real)
    return {
        int(k): (
            float(np.median(e.frequency_hz[mode == k])),
            np.median(signed[mode == k], axis=0),
            np.median(result.shape_std[mode == k], axis=0),
        )
        for k in sorted(set(mode.tolist()))
    }


#: what the ``--plot`` title calls each excitation's joint estimation
JOINT_METHODS = {'ambient': 'joint SSI-cov', 'free': 'joint free-decay fit'}


def plot_shapes(
    path: str, title: str, result: JointEstimates, unit: str = UNKNOWN_UNIT, excitation='ambient'
):
    """``--plot`` of a joint run: each mode's frequency over time with its std (the stabilisation
    over windows), one strip a mode with its own scale (close modes, 1.24 and 1.29 Hz, do not
    overlap), and each mode's shape (bars of the channel amplitudes, error bars their std);
    returns the Figure. Without an estimate: one panel saying so."""
    from .plotting import mode_colour, pyplot

    plt = pyplot()
    e = result.estimates
    mode = renumber(e.frequency_hz, e.mode, e.t)  # as the summary numbers them
    shapes = mode_shapes(result, mode)
    cols, rows = max(1, len(shapes)), max(1, len(shapes))
    fig = plt.figure(figsize=(max(8.0, 2.4 * cols), 3.8 + 0.75 * rows))
    outer = fig.add_gridspec(2, 1, height_ratios=(0.75 * rows, 3.2), hspace=0.28)
    top = outer[0].subgridspec(rows, 1, hspace=0.12)
    bottom = outer[1].subgridspec(1, cols, wspace=0.35)
    strips = [fig.add_subplot(top[0])]
    strips += [fig.add_subplot(top[i], sharex=strips[0]) for i in range(1, rows)]
    for ax, (k, (f, _, _)) in zip(strips, shapes.items()):
        m = mode == k
        ax.errorbar(e.t[m], e.frequency_hz[m], yerr=e.frequency_std_hz[m], fmt='.', ms=3,
                    lw=0.5, color=mode_colour(k))  # fmt: skip
        ax.set_ylabel(f'mode {k}\n{f:.3f} Hz', fontsize='small', rotation=0, ha='right',
                      va='center')  # fmt: skip
        ax.tick_params(labelsize='x-small')
        ax.grid(alpha=0.3)
    for ax in strips[:-1]:
        ax.tick_params(labelbottom=False)
    strips[-1].set_xlabel('time (s)', fontsize='small')
    method = JOINT_METHODS[excitation]
    strips[0].set_title(
        f'{title}: {method} over {len(result.channels)} channels: frequency (Hz) over time, '
        'one strip a mode (error bars: 1 std)',
        fontsize='small',
    )
    if not shapes:
        strips[0].text(0.5, 0.5, 'no estimate', transform=strips[0].transAxes, ha='center')
    x = np.arange(len(result.channels))
    for col, (k, (f, amp, std)) in enumerate(shapes.items()):
        sub = fig.add_subplot(bottom[col])
        sub.bar(x, amp, yerr=std, color=mode_colour(k), capsize=2)
        sub.axhline(0.0, color='k', lw=0.5)
        sub.set_xticks(x, result.channels, rotation=60, fontsize='small')
        sub.set_ylim(-1.05, 1.05)
        sub.set_title(f'mode {k}: {f:.3f} Hz', fontsize='small')
        if col == 0:
            sub.set_ylabel(f'shape ({unit}, normalised)')
    fig.subplots_adjust(left=0.1, right=0.98, top=0.95, bottom=0.1)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return fig


def run_joint(args, config: EstimatorConfig, names, json_row, prog: str, warn=None) -> int:
    """``analyze --columns`` or ``--components`` with two or more channels ``names``: estimates
    with their shapes on stdout, the counters and the summary on stderr, ``--plot``,
    ``--report``; ``warn`` (signal, prog) says what a bag's read skipped. Bad input raises
    (CsvError, BagError, ValueError, GeometryError) before anything is printed."""
    t, y, names, signals, origin, counters = read_joint(args, names)
    geometry = getattr(args, 'loaded_geometry', None)
    if geometry is not None:
        geometry.check_channels(names)
    config, decision, notes = prepare(args, config, t, y, len(names), prog)
    estimator, result = joint_run(t, y, names, config)
    table = rows(result)
    extra = ''
    if signals:
        if warn is not None:
            for signal in signals:
                warn(signal, prog)
        for row in table:
            row['stamp_ns'] = origin + round(row['t'] * 1e9)
        skipped = sum(signal.skipped for signal in signals)
        extra = f', messages_without_component={skipped}' if skipped else ''
        extra += f', corrupt_records={sum(signal.corrupt for signal in signals)}'
        extra += ''.join(f', {k}={v}' for k, v in counters.items())
    print_rows(table, args.format, json_row)
    for line in notes:
        print(line, file=sys.stderr)
    print(
        f'{prog}: channels={",".join(names)}, '
        + ', '.join(f'{k}={v}' for k, v in estimator.counters.items())
        + extra,
        file=sys.stderr,
    )
    e = result.estimates
    why = '' if len(e) else explain_no_estimate(estimator.counters, None, config, decision)
    if why:
        print(f'{prog}: no estimate: {why}', file=sys.stderr)
    mode = renumber(e.frequency_hz, e.mode, e.t)  # by identity (the summary's numbers)
    modes = summarise_modes(e.frequency_hz, e.damping, mode, e.t)
    for line in summary_lines(modes, config.excitation != 'free'):
        print(f'{prog}: ' + line, file=sys.stderr)
    missing = peaks_without_mode(config, decision, [m.frequency_hz for m in modes])
    if missing:
        print(f'{prog}: ' + missing, file=sys.stderr)
    for k, (f, amp, _) in mode_shapes(result, mode).items():
        shape = ', '.join(f'{n} {a:+.2f}' for n, a in zip(names, amp))
        print(f'{prog}: mode {k} ({f:.3f} Hz) shape: {shape}', file=sys.stderr)
    unit = signal_unit(names[0].rsplit(':', 1)[-1]) if signals else UNKNOWN_UNIT
    if args.plot:
        plot_shapes(args.plot, str(args.input), result, unit, config.excitation)
    if getattr(args, 'report', None):
        report_joint(args, config, (t, y, unit), result, estimator.counters, why)
    return 0


def report_joint(args, config, samples, result: JointEstimates, counters, why) -> None:
    """``--report`` of a joint run of the channels' ``samples`` (t, Y, their unit); ``why``:
    why nothing was estimated ('' if something was)."""
    from .report import Record, command_line, write_report

    t, y, unit = samples
    record = Record(
        str(args.input),
        command_line(args),
        tuple(result.channels),
        t,
        y,
        result.estimates,
        config,
        dict(counters),
        shapes=result.shapes,
        unit=unit,
        why=why,
    )
    path = write_report(args.report, record, getattr(args, 'loaded_geometry', None))
    print(f'analyze: report written to {path}', file=sys.stderr)
