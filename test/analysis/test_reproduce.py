# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The paper's Figs. 1 and 2, reproduced (``vib-estimator reproduce``)."""

import re

import numpy as np
import pytest

from vib_estimator.analysis import reproduce
from vib_estimator.cli import main


def test_fig1_invariant_filtering_is_within_one_percent_by_0_1_s():
    r = reproduce.fig1()
    assert r.error_at_0_1 < 0.01
    assert r.median_after_0_1 < 0.1 * r.median_after_0_1_unfiltered


def test_fig2_shape_with_the_printed_test():
    r = reproduce.fig2(**reproduce.PAPER_TEST)
    assert r.mae[0] < 1e-3  # undamped: within the tolerance
    assert np.all(np.diff(r.mae) > 0)  # MAE grows with zeta_n
    assert np.all(r.convergence_time < 0.5)  # a fraction of a period


def test_fig2_package_defaults_are_exact_when_undamped():
    r = reproduce.fig2(zetas=[0.0, 0.005])
    assert r.mae[0] < 1e-9 and r.mae[1] < 1e-3
    assert np.allclose(r.convergence_time, 0.5, atol=0.01)


def test_cli_prints_the_figures_numbers_and_writes_them(tmp_path, capsys):
    """The numbers the command prints are the paper's claims: Fig. 1's filtered estimate within
    1 % of 10 rad/s from 0.1 s on; Fig. 2's table, one row per zeta_n, the paper's test's MAE
    growing with zeta_n, the package defaults and the damped model exact when undamped."""
    png = tmp_path / 'fig1.png'
    assert main(['reproduce', 'fig1', '--out', str(png)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[-1] == f'wrote {png}' and png.is_file()  # the figure itself: its own tests
    rows = {float(ln.split()[0]): [float(v) for v in ln.split()[1:]] for ln in lines[2:8]}
    assert sorted(rows) == [0.05, 0.1, 0.2, 0.3, 0.5, 0.9]
    assert all(abs(rows[when][0] / 10 - 1) < 0.01 for when in rows if when >= 0.1), rows
    error = re.search(
        r'error at t = 0.1 s: ([0-9.]+) %.*: ([0-9.]+) % with invariant filtering, '
        r'([0-9.]+) % without',
        lines[8],
    )
    at_0_1, filtered, unfiltered = (float(v) for v in error.groups())
    assert at_0_1 < 1.0 and filtered < 0.1 * unfiltered
    assert abs(rows[0.1][0] / 10 - 1) == pytest.approx(at_0_1 / 100, abs=1e-4)  # one number

    png = tmp_path / 'fig2.png'
    assert main(['reproduce', 'fig2', '--out', str(png)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[-1] == f'wrote {png}' and png.is_file()
    table = np.array([[float(v) for v in ln.split()] for ln in lines[3:-2]])
    assert table.shape == (len(reproduce.FIG2_ZETAS), 7)
    np.testing.assert_allclose(table[:, 0], reproduce.FIG2_ZETAS, atol=5e-4)
    printed_test, defaults, damped = table[:, 1:3], table[:, 3:5], table[:, 5:7]
    assert printed_test[0, 1] < 1e-3 and np.all(np.diff(printed_test[:, 1]) > 0)
    assert np.all(printed_test[:, 0] < 0.5)
    assert defaults[0, 1] < 1e-9 and defaults[0, 0] == pytest.approx(0.5, abs=0.01)
    assert np.all(damped[:, 1] < 1e-9) and np.allclose(damped[:, 0], 0.5, atol=0.01)


def test_fig2_damped_model_is_exact_for_every_zeta():
    r = reproduce.fig2(model='damped-sinusoid')
    assert np.all(r.mae < 1e-9)
    assert np.allclose(r.convergence_time, 0.5, atol=0.01)
