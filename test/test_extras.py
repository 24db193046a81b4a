# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""An optional extra that is missing or fails to load costs one warning line and its fallback."""

import contextlib

import pytest

from vib_estimator.core import threads
from vib_estimator.extras import FALLBACKS, forget, optional


@pytest.mark.parametrize('package', sorted(FALLBACKS))
@pytest.mark.parametrize(
    'error', [ImportError('No module named x'), RuntimeError('module compiled against ABI 0x2')]
)
def test_a_missing_or_broken_extra_is_none_after_one_warning_line(
    package, error, break_extra, capsys
):
    break_extra(package, error)
    assert optional(package) is None
    assert optional(package + '.sub') is None and optional(package) is None  # said once
    lines = capsys.readouterr().err.splitlines()
    assert lines == [
        f'vib_estimator: warning: optional package {package} unavailable '
        f'({type(error).__name__}: {error}): {FALLBACKS[package]}'
    ]


def test_an_extra_that_loads_is_returned_silently(break_extra, capsys):
    forget()  # imported afresh (break_extra's teardown restores what the run found)
    module = optional('tqdm')
    assert module is not None and module.__name__ == 'tqdm' and optional('tqdm') is module
    assert capsys.readouterr().err == ''
    with pytest.raises(ValueError, match='not an optional extra'):
        optional('numpy')  # a requirement: its failure must not pass silently


def test_without_threadpoolctl_blas_threads_are_left_alone(break_extra, capsys):
    break_extra('threadpoolctl', OSError('libgomp.so.1: cannot open shared object file'))
    threads.blas_controller.cache_clear()
    try:
        assert isinstance(threads.one_blas_thread(), contextlib.nullcontext)
        assert threads.single_blas_thread(lambda x: 2 * x)(21) == 42
    finally:
        threads.blas_controller.cache_clear()
    assert capsys.readouterr().err.count('threadpoolctl unavailable') == 1
