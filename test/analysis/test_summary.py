# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``analyze``'s summary never gives a confident wrong answer: a frequency that moved is
summarised per stretch and shaped for the last one; a mode on too few estimates is tentative;
the modes of an identifier are never pooled; the default CSV column is named."""

import re
from pathlib import Path

import numpy as np
import pytest

from vib_estimator.analysis.summary import (
    STRETCH_REL,
    renumber,
    shaped_mode,
    stretches,
    summarise_modes,
    summary_lines,
)
from vib_estimator.cli import main

ROOT = Path(__file__).resolve().parents[2]


def steps(levels, each, scatter, seed=0):
    """Estimates in time order: ``each`` at each frequency of ``levels``, relative ``scatter``."""
    rng = np.random.default_rng(seed)
    f = np.repeat(levels, each) * (1 + scatter * rng.standard_normal(len(levels) * each))
    return f, np.arange(len(f), dtype=float)


def test_a_steady_mode_is_one_stretch_and_a_moved_one_three():
    # a steady mode scattering by 1 % (several times the scatter of a real mode's estimates)
    f, _ = steps([5.0], 60, 0.01)
    assert len(stretches(f)) == 1
    # one estimate 20 % off is an outlier, not a move
    f[30] *= 1.2
    assert len(stretches(f)) == 1
    # three tip masses (Section 5.5: 1.64, 1.33, 1.15 Hz; 19 % and 14 % apart)
    f, _ = steps([1.6395, 1.3306, 1.1482], 4, 0.001)
    parts = stretches(f)
    assert [len(p) for p in parts] == [4, 4, 4]
    # a move of twice the threshold is found, one of half of it is not
    for move, found in ((2 * STRETCH_REL, 2), (0.5 * STRETCH_REL, 1)):
        f, _ = steps([2.0, 2.0 * (1 + move)], 6, 0.001)
        assert len(stretches(f)) == found


def test_the_summary_of_a_moved_mode_is_per_stretch_and_shapes_the_last():
    f, t = steps([1.6395, 1.3306, 1.1482], 4, 0.001)
    modes = summarise_modes(f, np.full(len(f), np.nan), None, t)
    assert [m.stretch for m in modes] == [1, 2, 3] and {m.stretches for m in modes} == {3}
    assert [round(m.frequency_hz, 2) for m in modes] == [1.64, 1.33, 1.15]
    assert (modes[2].t_first, modes[2].t_last) == (8.0, 11.0)
    assert shaped_mode(modes) is modes[2]
    text = '\n'.join(summary_lines(modes))
    assert 'the frequency moved' in text
    # the shaper is designed for the last stretch, its spread that of the stretch alone
    command = text.splitlines()[-1]
    assert re.search(r'initial_frequency_hz:=1\.14[0-9]*', command)
    assert 'shaper:=zvd' in command
    # without the times the modes are pooled as before (one summary)
    (pooled,) = summarise_modes(f, np.full(len(f), np.nan))
    assert pooled.stretches == 1 and pooled.spread_rel > 0.1


def test_modes_renumbered_by_a_lower_one_found_later_are_summarised_by_identity():
    """An estimator numbers its published modes by frequency: a 17 Hz mode is 1 until a 5 Hz one
    publishes, then 2 (the 20 s record of test_ambient). The summary follows each mode, not its
    number: two modes, neither moved. A mode of one number that moves where no other mode is
    stays one mode of two stretches; two modes 3 % apart at the same times stay two."""
    rng = np.random.default_rng(0)
    t = np.array([12, 13, 14, 15, 16, 16, 17, 17, 18, 18, 19, 19], dtype=float)
    mode = np.array([1, 1, 1, 1, 1, 2, 1, 2, 1, 2, 1, 2])
    f = np.where((mode == 2) | (t < 16), 17.0, 5.0) * (1 + 0.001 * rng.standard_normal(len(t)))
    assert renumber(f, mode, t).tolist() == [2, 2, 2, 2, 1, 2, 1, 2, 1, 2, 1, 2]
    modes = summarise_modes(f, np.full(len(f), np.nan), mode, t)
    assert [(m.mode, m.count, m.stretches) for m in modes] == [(1, 4, 1), (2, 8, 1)]
    assert [round(m.frequency_hz) for m in modes] == [5, 17]
    assert 'moved' not in '\n'.join(summary_lines(modes))
    # the mode tracker's first estimate, 13.26 Hz as mode 1 before the 10 Hz mode was found,
    # continues the 13 Hz mode (its estimates come at their own times, not with the others')
    t = np.concatenate([[0.0], np.arange(1.0, 10.0), np.arange(1.5, 10.0)])
    mode = np.repeat([1, 1, 2], [1, 9, 9])
    f = np.repeat([13.26, 10.0, 13.0], [1, 9, 9])
    assert renumber(f, mode, t).tolist() == [2] + [1] * 9 + [2] * 9
    modes = summarise_modes(f, np.full(len(f), np.nan), mode, t)
    assert [(m.mode, m.count, m.stretches) for m in modes] == [(1, 9, 1), (2, 10, 1)]
    # mode 1 moves from 1.33 to 1.15 Hz (a tip mass) beside a steady mode 2 at 3 Hz
    t = np.repeat(np.arange(8.0), 2)
    mode = np.tile([1, 2], 8)
    f = np.where(mode == 2, 3.0, np.where(t < 4, 1.33, 1.15))
    assert renumber(f, mode, t).tolist() == mode.tolist()
    modes = summarise_modes(f, np.full(len(f), np.nan), mode, t)
    assert [(m.mode, m.stretch, m.stretches) for m in modes] == [(1, 1, 2), (1, 2, 2), (2, 1, 1)]
    # a close pair (3 % apart, within STRETCH_REL) seen together keeps its numbers, also when
    # one of it is missing from an analysis (the other keeps its own)
    f = np.where(mode == 1, 1.2276, 1.2645)
    keep = np.ones(len(f), bool)
    keep[[4, 9]] = False  # mode 1 missing at t = 2, mode 2 at t = 4
    assert renumber(f[keep], mode[keep], t[keep]).tolist() == mode[keep].tolist()


def test_a_mode_on_too_few_estimates_is_tentative_and_not_shaped():
    # two estimates (a stray pair) are too few to shape for; ten of one mode are a mode
    few, many = 2, 10
    f = np.concatenate([np.full(few, 1.37), np.full(many, 3.85)])
    mode = np.concatenate([np.full(few, 1), np.full(many, 2)])
    t = np.arange(len(f), dtype=float)
    modes = summarise_modes(f, np.full(len(f), 0.01), mode, t)
    assert [m.tentative for m in modes] == [True, False]
    lines = summary_lines(modes)
    assert 'tentative' in lines[1]
    assert 'initial_frequency_hz:=3.85' in lines[-1]  # the lowest mode that is not tentative
    assert 'below it are tentative' in lines[-2]
    # nothing but tentative modes: no shaper, and why
    lines = summary_lines(summarise_modes(f[:few], np.full(few, 0.01), mode[:few], t[:few]))
    assert shaped_mode(summarise_modes(f[:few], np.full(few, 0.01))) is None
    assert lines[-1].startswith('no input shaper recommended')
    assert not any('ros2 run' in line for line in lines)


def test_analyze_gives_both_modes_of_a_short_driven_record(tmp_path, capsys):
    """``analyze`` with no option on 20 s of 5 Hz (variance 1) and 17 Hz (0.3), white-noise
    driven: both modes, each summarised once (the 17 Hz mode, numbered 1 before the 5 Hz one
    published, did not "move"), the shaper for the lowest, no peak without a mode (before: 17 Hz
    alone, a shaper for it, and no word of the record's strongest peak)."""
    from vib_estimator.sim.ambient import ambient_record

    t, y, _ = ambient_record(20, 500, [(5.0, 0.01, 1.0), (17.0, 0.005, 0.3)], 20, 0)
    path = tmp_path / 'short.csv'
    np.savetxt(path, np.c_[t, y], delimiter=',', header='time_s,y', comments='', fmt='%.6f')
    assert main(['analyze', str(path), '--format', 'csv']) == 0
    err = capsys.readouterr().err
    found = re.findall(r'mode (\d): f = ([0-9.]+)', err)
    assert [(k, round(float(f))) for k, f in found] == [('1', 5), ('2', 17)], err
    assert 'moved' not in err and 'no mode at' not in err
    assert re.search(r'initial_frequency_hz:=(4\.9|5\.0)', err), err


def test_analyze_summarises_a_bag_whose_frequency_moved_per_stretch(capsys):
    assert main(['analyze', str(ROOT / 'bags' / 'arm_5_5'), '--format', 'csv']) == 0
    err = capsys.readouterr().err
    assert 'the frequency moved during the record (3 stretches' in err
    # each stretch within 0.5 % of its tip mass's true frequency (Eq. 23)
    found = [float(x) for x in re.findall(r's: f = ([0-9.]+) ', err)]
    assert len(found) == 3
    assert np.allclose(found, [1.6395, 1.3306, 1.1482], rtol=5e-3)
    command = err.strip().splitlines()[-1]
    assert (
        abs(float(re.search(r'initial_frequency_hz:=([0-9.]+)', command)[1]) / 1.1482 - 1) < 5e-3
    )


def test_an_identifier_s_modes_are_summarised_apart(tmp_path, capsys):
    from vib_estimator.sim.ambient import ambient_record

    t, y, _ = ambient_record(90, 200, [(2.0, 0.01, 1.0), (7.0, 0.01, 0.6)], 25, 3)
    path = tmp_path / 'driven.csv'
    np.savetxt(path, np.column_stack([t, y]), delimiter=',', header='t,y', comments='')
    assert main(['analyze', str(path), '--excitation', 'ambient', '--format', 'csv']) == 0
    err = capsys.readouterr().err
    found = [float(x) for x in re.findall(r'mode \d: f = ([0-9.]+) ', err)]
    assert len(found) == 2 and np.allclose(found, [2.0, 7.0], rtol=0.02)
    command = err.strip().splitlines()[-1]
    assert abs(float(re.search(r'initial_frequency_hz:=([0-9.]+)', command)[1]) / 2.0 - 1) < 0.01


def test_the_default_column_is_named_and_the_others_listed_when_it_gives_nothing(tmp_path, capsys):
    t = np.arange(0, 6, 0.002)
    ring = 0.2 * np.exp(-0.05 * t) * np.sin(2 * np.pi * 1.8 * t)
    path = tmp_path / 'rig.csv'
    np.savetxt(
        path,
        np.column_stack([t, np.zeros_like(t), ring]),
        delimiter=',',
        header='time_s,hub,tip',
        comments='',
    )
    assert main(['analyze', str(path)]) == 0
    err = capsys.readouterr().err
    assert 'analyze: column hub (the first after the time, the default; the others: tip' in err
    assert "column hub gave no estimate; the file's other columns: tip" in err
    # a comment line naming the columns names them (no header row)
    path.write_text(
        '# time_s,tip_g  (a note, with a comma)\n' + '\n'.join(f'{a},{b}' for a, b in zip(t, ring))
    )
    assert main(['analyze', str(path), '--column', 'tip_g', '--format', 'csv']) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) > 2 and abs(float(out[1].split(',')[1]) / 1.8 - 1) < 0.01


@pytest.mark.parametrize('factor', [1e-3, 1e3])
def test_an_identifier_s_undamped_line_is_named_and_never_shaped_for(monkeypatch, factor):
    """The simulated arm moved every 4 s (benchmarks/bench_periodic.py): the identifier's modes
    were its cycle's 5th harmonic, 0.625 Hz, and 11th, 1.375 Hz, at damping ratios of ~1e-5, and
    the arm's mode, 1.331 Hz at 0.36 %: the shaper is designed for 1.331 Hz, the two lines are
    named as such. A free decay's modes (``identified`` False) are summarised as before. At
    ``UNDAMPED`` x 0.001 the 0.625 Hz line is shaped for; x 1000 the mode is a line too."""
    from vib_estimator.analysis import summary

    f = np.repeat([0.625, 1.331, 1.375], [11, 29, 16])
    zeta = np.repeat([1.5e-5, 3.6e-3, 1e-5], [11, 29, 16])
    mode = np.repeat([1, 2, 3], [11, 29, 16])

    def right():
        modes = summarise_modes(f, zeta, mode)
        lines = summary_lines(modes, identified=True)
        free = summary_lines(modes)
        low = shaped_mode(modes, identified=True)
        return (
            low is not None
            and low.frequency_hz == 1.331
            and 'initial_frequency_hz:=1.331' in lines[-1]
            and sum('undamped, a line of the drive' in line for line in lines) == 2
            and 'initial_frequency_hz:=0.625' in free[-1]
            and not any('undamped' in line for line in free)
        )

    assert right()
    monkeypatch.setattr(summary, 'UNDAMPED', summary.UNDAMPED * factor)
    assert not right()


def test_an_estimate_far_from_its_mode_is_counted_as_an_outlier():
    """Fifty estimates scattering by 0.1 % and one 3 % off (~30 robust stds: an estimate of
    another mode labelled this one): that one is the outlier, named in the summary, and it
    widens neither the std nor the spread."""
    rng = np.random.default_rng(0)
    f = np.append(2.0 * (1 + 0.001 * rng.standard_normal(50)), 2.06)
    (m,) = summarise_modes(f, np.full(len(f), 0.01))
    assert m.outliers == 1 and m.frequency_std_hz < 0.003
    assert '1 outlier(s)' in summary_lines([m])[1]
