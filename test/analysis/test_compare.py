# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``vib-estimator compare``: the definitions it measures by, the speed claim of Section 5.4, and a
smoke run of the command."""

from __future__ import annotations

import math

import numpy as np

from vib_estimator import cli
from vib_estimator.analysis import compare
from vib_estimator.sim import arm_model


def test_segments_of_the_three_mass_experiment():
    rec = arm_model.experiment_5_5(0)
    segs = compare.segments(rec.f_true)
    assert [round(f, 2) for _, _, f in segs] == [1.64, 1.33, 1.15]
    assert segs[0][0] == 0 and segs[-1][1] == len(rec.t)
    assert all(a[1] == b[0] for a, b in zip(segs, segs[1:]))


def test_tracked_index_needs_a_whole_period_within_tolerance():
    out = np.full(100, 1.0)
    out[10:20] = 1.1  # outside 2 %
    out[30] = np.nan  # no estimate: not tracked
    assert compare.tracked_index(out, 1.0, 0, 100, 10) == 0
    assert compare.tracked_index(out, 1.0, 5, 100, 10) == 20
    assert compare.tracked_index(out, 1.0, 5, 100, 11) == 31
    assert compare.tracked_index(out, 1.0, 5, 40, 10) == 20
    assert compare.tracked_index(out, 1.0, 21, 39, 10) is None  # 9 good samples, then NaN


def test_algebraic_is_at_least_three_times_faster_on_section_5_3():
    """Section 5.4: the algebraic method's first estimate within 2 % comes >= 3x sooner than any
    adaptive baseline's (or the DFT's) output settles within 2 % for one period."""
    t, y, f_true = compare.CASES[0].record(0)
    seg = compare.segments(f_true)[0]
    noise = compare.CASES[0].noise_std
    names = [compare.ALGEBRAIC] + [cls.name for cls in compare.TRACKERS]
    results = {
        name: compare.evaluate(
            compare.run_method(name, t, y), t, y, seg, noise, name in compare.ALGEBRAIC_CONFIGS
        )
        for name in names
    }
    first = results[compare.ALGEBRAIC].first
    assert 0 < first < 0.5  # "less than 0.5 s" (Section 5.4), ~half a period
    # a method whose output never stays within 2 % for a period (NaN) is slower than any bound;
    # the claim is measured against the trackers that do settle on this record
    settled = {
        name: results[name].tracked
        for name in (cls.name for cls in compare.TRACKERS)
        if math.isfinite(results[name].tracked)
    }
    assert {'Sliding DFT', 'Matrix pencil'} <= set(settled), settled
    assert all(tracked >= 3 * first for tracked in settled.values()), (settled, first)
    assert results[compare.ALGEBRAIC].tracked == first  # its first estimate holds


def test_compare_command_prints_every_method_and_writes_plots(tmp_path, capsys):
    md = tmp_path / 'table.md'
    assert (
        cli.main(
            ['compare', '--quick', '--seeds', '2', '--out', str(tmp_path), '--markdown', str(md)]
        )
        == 0
    )
    text = capsys.readouterr().out
    table = text[text.index('\ncase') + 1 : text.index('\namplitude-tuned')]
    blocks = [[ln.split() for ln in block.splitlines()] for block in table.split('\n\n')]
    assert len(blocks) == len(compare.TEXT_BLOCKS)
    assert max(len(ln) for ln in table.splitlines()) <= compare.TABLE_WIDTH
    for case in compare.CASES:
        n_segs = 3 if case.key == '5.5' else 1
        for method in compare.METHODS:
            for lines in blocks:
                rows = [ln for ln in lines if ln[0] == case.key and method.split()[0] in ln]
                assert len(rows) == n_segs, (case.key, method)
        # what the figure shows: test_pictures.py, on the Figure plot_case returns
        assert (tmp_path / f'compare_{case.key.replace(".", "_")}.png').is_file()
    # the algebraic method's and the DFT's rows are complete and finite (across the blocks)
    numbers = {}
    for lines in blocks:
        for ln in lines:
            if ln[0] in ('5.3', '5.5', 'fig1') and ln[2] in ('Algebraic', 'Sliding'):
                numbers.setdefault(tuple(ln[:3]), []).extend(
                    ln[3:] if ln[2] == 'Algebraic' else ln[4:]
                )
    assert len(numbers) == 2 * sum(3 if c.key == '5.5' else 1 for c in compare.CASES)
    for key, values in numbers.items():
        assert len(values) == len(compare.HEADER) - 1, key  # two durations in s (periods)
        assert all(math.isfinite(float(v.strip('()%'))) for v in values), key
    table = md.read_text()
    assert '7.0e-02' in table and '3.1e-05' in table
    assert all(m in table for m in compare.METHODS)


def test_amplitude_tuned_gains_come_from_the_grid_and_help_on_scoring_seeds():
    """The -A rows' gain is the paper's times a grid factor, chosen on seeds 1000+; on a scoring
    seed of Section 5.3 (0.27 N m) the tuned Mojiri-Bakhshai tracks, the paper's gains do not."""
    case = compare.CASES[0]
    gains = compare.tuned_gains(case)
    assert set(gains) == set(compare.AMPLITUDE_TUNED)
    for name, (cls, gain) in compare.AMPLITUDE_TUNED.items():
        factor = gains[name][gain] / compare.inspect.signature(cls).parameters[gain].default
        assert any(math.isclose(factor, k) for k in compare.GAIN_FACTORS), (name, factor)
    t, y, f_true = case.record(0)
    seg = compare.segments(f_true)[0]
    tuned, paper = (
        compare.evaluate(
            compare.run_method(name, t, y, gains.get(name)), t, y, seg, case.noise_std, False
        )
        for name in ('Mojiri-Bakhshai-A', 'Mojiri-Bakhshai')
    )
    assert math.isfinite(tuned.tracked) and math.isnan(paper.tracked)
    truth = seg[2]
    assert np.mean(np.square(tuned.values - truth)) < np.mean(np.square(paper.values - truth))


def test_compare_shows_a_progress_bar_on_a_terminal(monkeypatch, capsys):
    """``make compare`` runs minutes: on a terminal a bar counts the records (a pipe gets none)."""
    import sys

    from vib_estimator.analysis import outputs

    bars = []

    def counted(total, unit, desc=''):
        bar = real(total, unit, desc)
        bars.append((total, unit, bar))
        return bar

    real = outputs.progress
    monkeypatch.setattr(compare, 'progress', counted)
    monkeypatch.setattr(sys.stdout, 'isatty', lambda: True, raising=False)
    monkeypatch.setattr(sys.stderr, 'isatty', lambda: True, raising=False)
    compare.compare(1, compare.CASES[:1])
    ((total, unit, bar),) = bars
    assert (total, unit) == (1, 'record') and bar.n == 1
    assert '1/1' in capsys.readouterr().err  # drawn: the terminal gets the bar
