# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Shared fixtures: an isolated ROS domain per test run and a fresh rclpy context per test."""

from __future__ import annotations

import contextlib
import io
import os
import sys

import pytest
from hypothesis import settings

# Property tests draw the same examples on every run (CI must be deterministic) and keep no
# example database in the tree.
settings.register_profile('deterministic', derandomize=True, database=None)
settings.load_profile('deterministic')

# One DDS domain per test run (concurrent runs on one machine never see each other), and discovery
# kept on this host. Set before rclpy is imported anywhere.
os.environ.setdefault('ROS_DOMAIN_ID', str(1 + os.getpid() % 100))
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'


@pytest.fixture
def ros_context():
    """A fresh, initialised :class:`rclpy.Context`, shut down after the test."""
    import rclpy

    context = rclpy.Context()
    rclpy.init(context=context, domain_id=int(os.environ['ROS_DOMAIN_ID']))
    yield context
    context.try_shutdown()


@pytest.fixture
def executor(ros_context):
    """The package's executor, bound to the test's context; the nodes added to it are destroyed
    afterwards (their subscriptions would stay visible to the next test's processes)."""
    from vib_estimator.nodes.runner import make_executor

    ex = make_executor(context=ros_context)
    yield ex
    nodes = ex.get_nodes()
    ex.shutdown()
    for node in nodes:
        node.destroy_node()  # idempotent: a test may have destroyed it already


#: the optional extras the library imports on its in-process paths (CSV, --out, progress, BLAS)
EXTRAS_USED = ('pyarrow.csv', 'pyarrow.parquet', 'tqdm', 'threadpoolctl')


def _load_extras() -> None:
    """Import them once, now: one that is unavailable (pyarrow 26 beside numpy 1.26) writes its
    warning line at the start of the run, not into the captured stderr of whichever test happens
    to read a CSV first."""
    from vib_estimator.extras import optional

    for name in EXTRAS_USED:
        optional(name)


_load_extras()


@pytest.fixture
def break_extra(monkeypatch):
    """``break_extra(package, error)``: from now on importing the optional extra ``package`` or a
    submodule of it raises ``error`` (a missing package: ``ImportError``; one that fails as it
    loads: anything), as if it were not installed or broken; restored after the test."""
    from vib_estimator.extras import forget

    def breaker(package: str, error: BaseException = ImportError('not installed')) -> None:
        def hit(name):
            return name == package or name.startswith(package + '.')

        for name in [n for n in sys.modules if hit(n)]:
            monkeypatch.delitem(sys.modules, name)

        class Broken:
            @staticmethod
            def find_spec(name, path=None, target=None):
                if hit(name):
                    raise error
                return None

        monkeypatch.setattr(sys, 'meta_path', [Broken(), *sys.meta_path])
        forget()

    yield breaker
    monkeypatch.undo()
    forget()
    with contextlib.redirect_stderr(io.StringIO()):  # said at the start of the run already
        _load_extras()


@pytest.fixture(autouse=True)
def fresh_uncompiled_budget(monkeypatch):
    """Each test starts as a new process would: with its whole budget of uncompiled batch
    samples (``core.estimator.UNCOMPILED``, which a process spends across records), so that what
    earlier tests ran does not decide whether a later one runs compiled."""
    from vib_estimator.core import estimator

    monkeypatch.setattr(estimator.UNCOMPILED, 'spent', 0)
