"""Helpers for in-process node tests (import from test modules)."""
from __future__ import annotations

import time


def spin_until(executor, predicate, timeout=10.0):
    """Spin ``executor`` until ``predicate()`` is true; return whether it became true in time."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        executor.spin_once(timeout_sec=0.01)
    return predicate()
