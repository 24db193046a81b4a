"""The paper's Figs. 1 and 2, reproduced (``vib-estimator reproduce``)."""
import numpy as np

from vib_estimator.analysis import reproduce
from vib_estimator.cli import main


def test_fig1_invariant_filtering_is_within_one_percent_by_0_1_s():
    r = reproduce.fig1()
    assert r.error_at_0_1 < 0.01
    assert r.median_after_0_1 < 0.1 * r.median_after_0_1_unfiltered


def test_fig2_shape_with_the_printed_test():
    r = reproduce.fig2(**reproduce.PAPER_TEST)
    assert r.mae[0] < 1e-3                          # undamped: within the tolerance
    assert np.all(np.diff(r.mae) > 0)               # MAE grows with zeta_n
    assert np.all(r.convergence_time < 0.5)         # a fraction of a period


def test_fig2_package_defaults_are_exact_when_undamped():
    r = reproduce.fig2(zetas=[0.0, 0.005])
    assert r.mae[0] < 1e-9 and r.mae[1] < 1e-3
    assert np.allclose(r.convergence_time, 0.5, atol=0.01)


def test_cli_writes_the_figures(tmp_path, capsys):
    for fig in ('fig1', 'fig2'):
        assert main(['reproduce', fig, '--out', str(tmp_path / f'{fig}.png')]) == 0
        assert (tmp_path / f'{fig}.png').stat().st_size > 10_000
    assert 'zeta_n' in capsys.readouterr().out


def test_fig2_damped_model_is_exact_for_every_zeta():
    r = reproduce.fig2(model='damped-sinusoid')
    assert np.all(r.mae < 1e-9)
    assert np.allclose(r.convergence_time, 0.5, atol=0.01)
