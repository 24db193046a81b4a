# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""A batch run (analyze) whose kernels would have to be compiled first runs uncompiled for its
first UNCOMPILED_SAMPLES samples, then compiled; compiled from the start when its kernels cost
nothing (in memory or numba's cache); read-only input costs no second compile."""

from __future__ import annotations

import numpy as np
import pytest

from vib_estimator.core import EstimatorConfig, create_estimator
from vib_estimator.core import estimator as E
from vib_estimator.core import kernel as K
from vib_estimator.core.factory import batch_estimator, create_uncompiled


def _decay(n, rate=500.0):
    t = np.arange(n) / rate
    rng = np.random.default_rng(3)
    return t, np.exp(-0.2 * t) * np.sin(2 * np.pi * 5.0 * t) + 0.001 * rng.standard_normal(n)


@pytest.mark.parametrize(
    'config', [EstimatorConfig(), EstimatorConfig(modes=3)], ids=['default', 'modes: 3']
)
def test_a_batch_run_switches_to_its_compiled_kernels_at_uncompiled_samples(config, monkeypatch):
    """In a process that has run UNCOMPILED_SAMPLES - 300 samples uncompiled (``UNCOMPILED``),
    the uncompiled estimator runs 300 more uncompiled, then compiled; a whole short record in a
    fresh process stays uncompiled. The
    estimates are those of the compiled estimator (the mode tracker's within 1e-9: subspace's
    reassociated sums)."""
    switched_at = []
    t, y = _decay(1200)
    estimator = create_uncompiled(config)
    compiled = type(estimator).compiled

    def spy(self):
        switched_at.append(self.counters['received'])
        compiled(self)

    monkeypatch.setattr(type(estimator), 'compiled', spy)
    monkeypatch.setattr(E.UNCOMPILED, 'spent', E.UNCOMPILED_SAMPLES - 300)
    got = E.run_batch(estimator, t, y)
    assert switched_at == [300] and not estimator.interpreted
    want = create_estimator(config).process(t, y)
    assert len(got) == len(want) > 3 and list(got.t) == list(want.t)
    np.testing.assert_allclose(
        got.frequency_hz, want.frequency_hz, rtol=1e-9 if config.modes else 0
    )
    monkeypatch.setattr(E.UNCOMPILED, 'spent', 0)  # a fresh process
    short = create_uncompiled(config)
    E.run_batch(short, t, y)
    assert short.interpreted and switched_at == [300]  # 1200 samples, all uncompiled


def test_a_batch_run_is_compiled_from_the_start_when_that_costs_nothing(monkeypatch):
    config = EstimatorConfig()
    t, y = _decay(1200)
    create_estimator(config).process(t, y)  # compiled in this process: in memory
    assert not batch_estimator(config).interpreted
    monkeypatch.setattr(E.FrequencyEstimator, 'kernels_available', lambda self: False)
    assert batch_estimator(config).interpreted  # would compile: uncompiled first
    assert not batch_estimator(config.replace(excitation='ambient')).interpreted  # none to run


@pytest.mark.parametrize(
    'config', [EstimatorConfig(), EstimatorConfig(modes=3)], ids=['default', 'modes: 3']
)
def test_short_records_in_one_process_compile_once_they_add_up(config, monkeypatch):
    """The budget of uncompiled samples is the process's (``UNCOMPILED``): a survey's worker
    running short record after short record (each under ``UNCOMPILED_SAMPLES``) compiles in the
    record that brings it over, and the next starts compiled -- each stayed uncompiled, its
    kernels never compiled nor cached, until 7 Dec 2026."""
    switched_at = []
    t, y = _decay(2000)
    compiled = type(create_uncompiled(config)).compiled

    def spy(self):
        switched_at.append(self.counters['received'])
        compiled(self)

    monkeypatch.setattr(type(create_uncompiled(config)), 'compiled', spy)
    monkeypatch.setattr(type(create_uncompiled(config)), 'kernels_available', lambda self: False)
    monkeypatch.setattr(E, 'UNCOMPILED_SAMPLES', 4500)
    runs = []
    for _ in range(4):
        estimator = batch_estimator(config)
        runs.append((estimator.interpreted, E.run_batch(estimator, t, y)))
    assert [r[0] for r in runs] == [True, True, True, False]
    assert switched_at == [500, 0]  # 2000 + 2000 + 500 uncompiled; the fourth from the start
    want = create_estimator(config).process(t, y)
    for _, got in runs:
        np.testing.assert_allclose(
            got.frequency_hz, want.frequency_hz, rtol=1e-9 if config.modes else 0
        )


def test_read_only_input_runs_the_kernel_compiled_for_writeable_arrays():
    """A CSV's time column comes read-only (pyarrow); numba would compile every kernel again for
    that type, a cost ``vib-estimator warmup`` does not cover."""
    t, y = _decay(1200)
    create_estimator(EstimatorConfig()).process(t, y)
    signatures = len(K.run.signatures)
    t.flags.writeable = False
    y.flags.writeable = False
    assert len(create_estimator(EstimatorConfig()).process(t, y)) > 3
    assert len(K.run.signatures) == signatures


def test_a_long_record_pays_the_compile_before_its_end(monkeypatch):
    """Four minutes at 500 Hz (120 000 samples): compiled after its first UNCOMPILED_SAMPLES
    uncompiled ones (~100 us each: a longer uncompiled stretch would cost more than the compile),
    with the compiled estimator's floats."""
    config = EstimatorConfig.paper()
    t, y = _decay(120_000)
    monkeypatch.setattr(E.FrequencyEstimator, 'kernels_available', lambda self: False)
    estimator = batch_estimator(config)
    got = E.EstimateArrays.concatenate(
        [
            E.run_batch(estimator, t[i : i + 20_000], y[i : i + 20_000])
            for i in range(0, len(t), 20_000)
        ]
    )
    assert not estimator.interpreted
    want = create_estimator(config).process(t, y)
    assert len(got) == len(want) > 100 and list(got.frequency_hz) == list(want.frequency_hz)
