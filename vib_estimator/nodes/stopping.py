# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""How a node's process takes SIGINT and SIGTERM, from its first instant (no rclpy: this module
is loaded before it).

Importing the node modules (rclpy, numba, scipy: about a second, more on a loaded machine) used to
be a window where Ctrl-C died of a ``KeyboardInterrupt`` traceback (exit -2). Now, when
``vib_estimator.nodes`` is imported by one of the package's :data:`EXECUTABLES` (:func:`early`), a
signal until :func:`~.runner.run` starts ends the process at once with exit 0: nothing has been
opened yet that needs closing (no DDS participant, no file). From then on a signal only asks the
spin loop to stop (:class:`StopRequest`): the callback in progress finishes, the node is destroyed,
rclpy is shut down, and the process exits 0.
"""

from __future__ import annotations

import os
import signal
import sys
import threading

#: the package's node executables (setup.py's console scripts into vib_estimator.nodes)
EXECUTABLES = frozenset(
    ('estimator_node', 'sim_node', 'shaper_node', 'bag_replayer', 'bag_recorder')
)
#: the signals that stop a node
SIGNALS = (signal.SIGINT, signal.SIGTERM)


#: whether this process is one of :data:`EXECUTABLES` (:func:`early` installed its handler)
_executable = False


def _exit_now(signum, frame) -> None:
    os._exit(0)


def in_executable() -> bool:
    """Whether this process is one of the package's node executables (its ``main`` ends the
    process; a test calling it in its own process is not)."""
    return _executable


def runs_a_node() -> bool:
    """Whether this process runs a node's ``main`` as its own: one of :data:`EXECUTABLES`, or
    ``python -m vib_estimator.nodes.<module>`` (the tests' way of starting one) -- not a test
    calling :func:`~.runner.run` in its own process."""
    spec = getattr(sys.modules.get('__main__'), '__spec__', None)
    return _executable or (spec is not None and spec.name.startswith(f'{__package__}.'))


def early(argv0: str) -> bool:
    """In the process of one of :data:`EXECUTABLES` (``argv0``, its command), with Python's own
    SIGINT handler still in place, or SIGINT ignored (a process a shell started in the background
    inherits that; :class:`StopRequest` takes SIGINT over anyway -- before, such a node missed a
    SIGINT sent while its modules loaded, and ended its process slowly: 10.4 s after SIGINT on a
    loaded machine, its final garbage collections not skipped): a signal ends it at once, exit
    0, until :class:`StopRequest` takes over. Returns whether it was installed."""
    if (
        os.path.basename(argv0) not in EXECUTABLES
        or threading.current_thread() is not threading.main_thread()
        or signal.getsignal(signal.SIGINT) not in (signal.default_int_handler, signal.SIG_IGN)
    ):
        return False
    global _executable
    _executable = True
    for signum in SIGNALS:
        signal.signal(signum, _exit_now)
    return True


class StopRequest:
    """SIGINT / SIGTERM set :attr:`requested` (between bytecodes, wherever the main thread is)
    instead of raising there; :func:`~.runner.run`'s loop stops at the next turn."""

    def __init__(self):
        self.requested = False
        for signum in SIGNALS:
            signal.signal(signum, self._request)

    def _request(self, signum, frame) -> None:
        self.requested = True
