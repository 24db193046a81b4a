# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The real flexible-link arm (``../shared/real-data/flexible_link_arm/flex8.csv``, issue 25).

A Quanser-type rig: strain gauge on the link, 1 mm quantisation, an offset of half the amplitude,
a second harmonic of 1.9 %; after a reference step at 2.83 s the link rings (period-by-period
1.60-1.65 Hz over 3.2-4.4 s) and from ~4.5 s the closed loop holds a limit cycle at 1.812 Hz
(SOURCE.md). The goals of the issue, with the default configuration: after 4.5 s >= 95 % of the
estimates within 2 % of 1.812 Hz, none beyond 5 %, about one per second; during the ringing
estimates within 5 % of the local frequency or none; consecutive estimates never contradict each
other. The paper's configuration (``--paper``) fails them: it alternates 1.43 / 2.59 Hz.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from vib_estimator.cli import main

ROOT = Path(__file__).resolve().parents[2]
#: ``../shared`` of the repository (a worktree may sit one level deeper: the nearest one above)
SHARED = next(
    (p / 'shared' for p in ROOT.parents if (p / 'shared' / 'real-data').is_dir()),
    ROOT.parent / 'shared',
)
FLEX8 = SHARED / 'real-data' / 'flexible_link_arm' / 'flex8.csv'
LIMIT_CYCLE_HZ = 1.812
#: the ringing's frequencies, period by period (upward crossings about the running mean)
RINGING_HZ = (1.60, 1.65)
RINGING_S = (3.2, 4.5)


def analyze(capsys, *options):
    assert (
        main(
            ['analyze', str(FLEX8), '--column', 'tip_deflection_m', '--format', 'jsonl', *options]
        )
        == 0
    )
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    return (np.array([r['t'] for r in rows]), np.array([r['frequency_hz'] for r in rows]))


def goal_failures(t, f):
    """What the estimates (t s, f Hz) miss of the issue's goals (an empty list: all met)."""
    failures = []
    late = f[t >= RINGING_S[1]]
    err = np.abs(late / LIMIT_CYCLE_HZ - 1)
    if len(late) < 5:
        failures.append(f'{len(late)} estimates after 4.5 s (5.5 s of limit cycle)')
    elif np.mean(err <= 0.02) < 0.95 or np.any(err > 0.05):
        failures.append(
            f'after 4.5 s {100 * np.mean(err <= 0.02):.0f} % within 2 %, '
            f'{np.sum(err > 0.05)} beyond 5 %'
        )
    steady = t[t >= RINGING_S[1]]
    if len(steady) > 1 and np.max(np.diff(steady)) > 1.0:
        failures.append(f'a gap of {np.max(np.diff(steady)):.2f} s between estimates')
    ring = f[(t >= RINGING_S[0]) & (t < RINGING_S[1])]
    if np.any((ring < 0.95 * RINGING_HZ[0]) | (ring > 1.05 * RINGING_HZ[1])):
        failures.append(f'ringing estimates {np.round(ring, 3)} beyond 5 % of {RINGING_HZ} Hz')
    jumps = np.abs(np.diff(f)) / f[:-1]
    if np.any(jumps > 0.05):
        failures.append(f'consecutive estimates {100 * np.max(jumps):.0f} % apart')
    return failures


@pytest.mark.skipif(not FLEX8.is_file(), reason='../shared/real-data is absent')
def test_defaults_meet_the_goals_on_the_real_arm_and_the_paper_configuration_does_not(capsys):
    t, f = analyze(capsys)
    assert goal_failures(t, f) == []
    paper_t, paper_f = analyze(capsys, '--paper')
    # the paper's model misses the offset: each half-period lobe gets its own frequency
    assert goal_failures(paper_t, paper_f)
    late = paper_f[paper_t >= RINGING_S[1]]
    assert np.min(late) < 1.5 and np.max(late) > 2.5


@pytest.mark.skipif(not FLEX8.is_file(), reason='../shared/real-data is absent')
def test_the_consistency_gate_holds_back_contradicting_half_periods(capsys):
    """The paper's model with the consistency gate on: its lobe estimates contradict each other,
    so none is published after 4.5 s (rather than a confident wrong number)."""
    t, _ = analyze(capsys, '--paper', '--consistency', '0.03')
    assert np.sum(t >= RINGING_S[1]) == 0
