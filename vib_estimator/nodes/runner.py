# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The one ``main`` every node of this package uses.

It holds the Jazzy idiom (``init`` / spin / shutdown / ``destroy_node`` / ``try_shutdown``) once,
so that the node modules only build their node.

Ctrl-C and SIGTERM only *ask* the spin loop to stop (:class:`.stopping.StopRequest`, a flag
checked between ``spin_once`` calls): rclpy's own handler raises ``KeyboardInterrupt`` or shuts
the context down wherever the signal lands, inside a timer or subscription callback included,
where it became a FATAL "Exception in callback" line, a ``RuntimeError`` from the executor (exit 1)
or rosout errors from a logger whose context had gone. Here the callback in progress finishes, the
node is destroyed, and the process exits 0 (before :func:`run`, while the modules load, a signal
ends the process at once: :mod:`.stopping`). The
executor is :class:`rclpy.experimental.EventsExecutor`: measured by ``benchmarks/bench_node.py`` it
sustains several times the message rate of the default ``SingleThreadedExecutor`` on this package's
workload (see the README's figures). Each node's participant talks UDP only unless the user
chooses its transports (:func:`stall_safe_transports`: shared memory left a node deaf for good
after a stall of its own, docs/nodes.md#never-deaf).
"""

from __future__ import annotations

import ctypes
import os
import re
import sys
import tempfile
import time
import warnings
from typing import Callable, Optional, Sequence

import rclpy
from rclpy._rclpy_pybind11 import InvalidHandle, RCLError
from rclpy.exceptions import NameValidationException
from rclpy.executors import ExternalShutdownException
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from ..errors import StartupError
from .stopping import StopRequest, in_executable, runs_a_node

#: rclpy's warning when a node that failed to be created is finalised
ROSOUT_FINI = 'Failed to fini rosout publisher'
#: rcl's error text cites its C sources (", at /project/src/rcl/arguments.c:356"); cut from there
_RCL_LOCATION = re.compile(r',? at /\S+:\d+')


def argument_error(err: Exception) -> str:
    """One line for an error rcl or rclpy raised about the command line (``-p``, ``-r``,
    ``--params-file``, a remapped or configured name): its message without source locations."""
    text = ' '.join(_RCL_LOCATION.sub('', str(err)).split())
    return text.removeprefix('failed to initialize rcl: ')


def init_or_error(args: Optional[Sequence[str]]) -> Optional[str]:
    """``rclpy.init(args=args)``; on a command line rcl refuses, the one-line reason (rcl's own log
    line about it, written to stderr during the call, is dropped; anything else is passed on)."""
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as captured:
        os.dup2(captured.fileno(), 2)
        try:
            rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
            error = None
        except RCLError as err:
            error = argument_error(err)
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        if error is None:
            captured.seek(0)
            sys.stderr.buffer.write(captured.read())
            sys.stderr.flush()
    return error


#: the Fast DDS environment variable that chooses a participant's transports (Fast DDS >= 2.13)
TRANSPORTS_VARIABLE = 'FASTDDS_BUILTIN_TRANSPORTS'
#: this package's nodes' default: UDP only. Fast DDS's shared-memory transport takes a reader that
#: has not read its port for about two health-check periods (1 s each) for dead -- a process
#: stopped or starved of CPU for 2 s -- and the writers and the reader, when it runs again,
#: re-create its port; in Fast DDS 2.14 one side can be left on a segment the other has removed,
#: and the node stays deaf to that writer for good (re-creating the subscription does not change
#: the participant's port). Over UDP a stalled reader only loses what its socket could not hold.
NODE_TRANSPORTS = 'UDPv4'
#: the Fast DDS variables naming an XML profiles file (2.x reads the first, 3.x the second)
PROFILES_VARIABLES = ('FASTRTPS_DEFAULT_PROFILES_FILE', 'FASTDDS_DEFAULT_PROFILES_FILE')
#: ... and so a default participant profile whose participant listens on UDPv4 only (its unicast
#: locators, any address). Needed besides :data:`NODE_TRANSPORTS`: with
#: ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST (the soak's, the suite's, many users') rmw_fastrtps
#: (Jazzy wheels) gives the participant shared memory whatever FASTDDS_BUILTIN_TRANSPORTS says --
#: the soak's estimator_node listened on shared-memory ports and went deaf for good after a 2-s
#: stop (docs/nodes.md#never-deaf). A UDPv4 locator list leaves it no shared-memory port to
#: listen on; it still writes to a peer's shared-memory port (the peer's reader is the one at
#: risk, not this node).
UDP_PROFILE = """<?xml version="1.0" encoding="UTF-8" ?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <participant profile_name="vib_estimator_udp" is_default_profile="true">
    <rtps>
      <defaultUnicastLocatorList>
        <locator><udpv4/></locator>
      </defaultUnicastLocatorList>
    </rtps>
  </participant>
</profiles>
"""


def udp_profile_file() -> str:
    """:data:`UDP_PROFILE` in a file (the temporary directory, one per user; written atomically,
    so nodes starting together never read half of it)."""
    path = os.path.join(tempfile.gettempdir(), f'vib_estimator_udp_profile_{os.getuid()}.xml')
    try:
        with open(path) as f:
            if f.read() == UDP_PROFILE:
                return path
    except OSError:
        pass
    fd, partial = tempfile.mkstemp(dir=os.path.dirname(path), suffix='.xml')
    with os.fdopen(fd, 'w') as f:
        f.write(UDP_PROFILE)
    os.replace(partial, path)
    return path


#: at most this many InvalidHandle errors in a row from the executor are skipped (see :func:`run`)
MAX_INVALID_HANDLES = 100


def stall_safe_transports(environ=os.environ) -> bool:
    """Set the nodes' transports (:data:`NODE_TRANSPORTS`) and, unless the user names a profiles
    file, the UDP-only profile (:data:`UDP_PROFILE`) -- all unless the user chose the transports
    (:data:`TRANSPORTS_VARIABLE` already set, e.g. ``DEFAULT`` for shared memory again); True when
    set. Before ``rclpy.init``: the participant reads them when it is created."""
    if environ.get(TRANSPORTS_VARIABLE):
        return False
    environ[TRANSPORTS_VARIABLE] = NODE_TRANSPORTS
    if not any(environ.get(name) for name in PROFILES_VARIABLES):
        environ[PROFILES_VARIABLES[0]] = udp_profile_file()
    return True


def make_executor(context=None):
    """Return the executor the package's nodes spin in (one place to change it)."""
    return EventsExecutor(context=context)


def spin_until(executor, predicate: Callable[[], bool], timeout: float) -> bool:
    """Spin ``executor`` until ``predicate()`` holds or ``timeout`` s pass; return ``predicate()``.

    Raises ``ExternalShutdownException`` when the executor's context is shut down (Ctrl-C).
    """
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and not predicate():
        if not executor.context.ok():
            raise ExternalShutdownException()
        executor.spin_once(timeout_sec=0.01)
    return predicate()


def spin_until_arrival(executor, arrived: list, predicate: Callable, timeout: float):
    """Spin ``executor`` until an item appended to ``arrived`` (a subscription's list) after this
    call satisfies ``predicate``; return it (AssertionError listing what arrived, on time-out)."""
    start = len(arrived)

    def found():
        return any(predicate(item) for item in arrived[start:])

    if not spin_until(executor, found, timeout):
        raise AssertionError(arrived[start:])
    return next(item for item in arrived[start:] if predicate(item))


def end_process(code: int) -> None:
    """End an executable's process with ``code`` once its node is destroyed and rclpy shut down
    (or at once, a node refusing to start: :func:`refuse`): Python's and C's output flushed, then
    ``os._exit``, without the interpreter's finalization.

    Measured on ``estimator_node`` (on ``sim_node`` at speed 10 for 50-70 s, its default deciding
    the identifier; SIGINT 3 s after the simulator stopped; both nodes at nice 10 beside two
    ``yes``): the node's own exit -- the spin left, the node destroyed (with it the process's DDS
    participant, the context's last node: its sockets closed, its peers told), rclpy shut down
    -- ended 0.02-0.14 s after the signal; the finalization that followed (module teardown and
    the libraries' destructors after the kernels' LLVM and numpy objects; its garbage
    collections frozen, before) took 0.3 s more beside two ``yes`` at nice 10, and 1.0-3.0 s
    beside two at nice 0: exits of 0.37-0.38 s and 1.3-3.1 s, now 0.17-0.19 s and 0.23-0.72 s.
    Nothing needs it: the node's files are closed by its ``destroy_node``, numba writes a cache
    file whole (a temporary file renamed) if a compile thread is cut short. (An ``os._exit``
    tried before, then reverted, was blamed for a next node's unanswered service in a test whose
    node, started by ``python -c``, no longer takes this path: docs/nodes.md.)"""
    sys.stdout.flush()
    sys.stderr.flush()
    try:  # and C's streams (rcutils logs to a buffered stdout with RCUTILS_LOGGING_USE_STDOUT)
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):
        pass
    os._exit(code)


def refuse(reason: str) -> int:
    """Print a node's refusal to start (one ``error:`` line) and return its exit code, 2; in a
    process that runs the node (:func:`~.stopping.runs_a_node`), end it there and then.

    Called inside the ``except`` clause, while the exception's traceback still holds the node its
    ``__init__`` left half-built (a ``StartupError`` raised after ``Node.__init__``, a topic
    name rcl refuses): ending the process there destroys nothing. Destroying that node's DDS
    participant while its peers come and go deadlocked Fast DDS 2.14 (``rcl_node_fini`` ->
    ``destroy_participant`` -> ``DomainParticipant::set_listener`` spinning while a discovery
    thread in ``onWriterDiscovery`` waits for the lock it holds; gdb, Dec 2026): twelve
    ``bag_replayer`` refusing bags at once (``test_unplayable_bags_are_refused_with_one_line``)
    left one spinning a core for good, in about one round of two. Its peers see the participant
    leave when its lease ends."""
    print(f'error: {reason}', file=sys.stderr)
    if runs_a_node():
        end_process(2)
    return 2


def run(
    factory: Callable[[], Node],
    args: Optional[Sequence[str]] = None,
    done: Optional[Callable[[Node], bool]] = None,
) -> int:
    """Initialise rclpy, build the node with ``factory`` and spin it until shutdown.

    ``done(node)``, when given, is polled between callbacks; spinning stops when it returns True
    (the bag replayer uses it to exit 0 at the end of a bag). Returns the process exit code: 2 for
    a :class:`StartupError` or a ROS argument rcl refuses (a malformed ``-p``/``-r``, a missing
    ``--params-file``, an invalid name given to a node: one ``error:`` line), else the node's
    ``exit_code`` read after it was destroyed (so an error while closing, e.g. a bag that cannot
    be finished at SIGINT, still fails the process).
    """
    stop = StopRequest()
    stall_safe_transports()
    error = init_or_error(args)
    if error is not None:
        print(f'error: {error}', file=sys.stderr)
        return 2
    node = None
    code = 0
    try:
        with warnings.catch_warnings():
            # a node whose creation failed (e.g. asked for DDS security the middleware lacks)
            # has no rosout publisher to finalise: rclpy's warning about it is not the error
            warnings.filterwarnings('ignore', ROSOUT_FINI, RuntimeWarning)
            node = factory()
        executor = make_executor()
        executor.add_node(node)
        skipped = 0
        while rclpy.ok() and not stop.requested and not (done is not None and done(node)):
            try:
                executor.spin_once(timeout_sec=0.1)
                skipped = 0
            except InvalidHandle:
                # a QoS event of an entity destroyed meanwhile (the watchdog's re-created
                # subscription: rclpy's EventsExecutor, ros2/rclpy#1644): skipped, unless it
                # never ends
                skipped += 1
                if skipped > MAX_INVALID_HANDLES:
                    raise
    except StartupError as err:
        code = refuse(str(err))
    except (NameValidationException, RCLError) as err:  # e.g. -p input_topic:=1bad
        code = refuse(argument_error(err))
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
            code = code or getattr(node, 'exit_code', 0)
        rclpy.try_shutdown()
    if in_executable():
        end_process(code)
    return code
