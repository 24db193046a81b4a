# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The nodes' one main (nodes/runner.py): the transports a node's participant talks over. Shared
memory left a node deaf for good after a stall of its own (docs/nodes.md#never-deaf): the nodes
talk UDP unless the user chose (the stall itself: test_soak.py)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import weakref

from vib_estimator.nodes import runner


def test_a_node_talks_udp_unless_the_user_chose_its_transports():
    environ = {}
    assert runner.stall_safe_transports(environ)
    profile = environ.pop('FASTRTPS_DEFAULT_PROFILES_FILE')
    assert environ == {'FASTDDS_BUILTIN_TRANSPORTS': 'UDPv4'}
    assert open(profile).read() == runner.UDP_PROFILE
    own = {'FASTRTPS_DEFAULT_PROFILES_FILE': '/my/profiles.xml'}  # the user's profiles kept
    assert runner.stall_safe_transports(own)
    assert own == {'FASTRTPS_DEFAULT_PROFILES_FILE': '/my/profiles.xml', **environ}
    chosen = {'FASTDDS_BUILTIN_TRANSPORTS': 'DEFAULT'}  # shared memory again, the user's choice
    assert not runner.stall_safe_transports(chosen)
    assert chosen == {'FASTDDS_BUILTIN_TRANSPORTS': 'DEFAULT'}


def test_the_node_executables_set_it_before_their_participant_exists(monkeypatch):
    """run() sets it before rclpy.init (the participant reads it when it is created)."""
    seen = []
    # empty: unset for the node; monkeypatch removes what run() sets (the suite's own nodes keep
    # theirs)
    monkeypatch.setenv('FASTDDS_BUILTIN_TRANSPORTS', '')

    def init_or_error(args):
        seen.append(runner.os.environ.get('FASTDDS_BUILTIN_TRANSPORTS'))
        return 'stopped here'

    monkeypatch.setattr(runner, 'init_or_error', init_or_error)
    assert runner.run(lambda: None, []) == 2
    assert seen == ['UDPv4']


#: a participant's threads, by name: Fast DDS names a shared-memory listener dds.shm.<port>
PARTICIPANT = """
import os, sys
from vib_estimator.nodes import runner
if sys.argv[1] == 'node':
    runner.stall_safe_transports()
import rclpy
rclpy.init()
node = rclpy.create_node('transports_probe')
tasks = os.listdir('/proc/self/task')
print(' '.join(open(f'/proc/self/task/{t}/comm').read().strip() for t in tasks))
"""


def listens_on_shared_memory(how: str, discovery: str) -> bool:
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ('FASTDDS_BUILTIN_TRANSPORTS', *runner.PROFILES_VARIABLES)
    }
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = discovery
    out = subprocess.run(
        [sys.executable, '-c', PARTICIPANT, how],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    return any(re.fullmatch(r'dds\.shm\.\d+', name) for name in out.stdout.split())


def test_a_node_listens_on_no_shared_memory_port_with_localhost_discovery():
    """With ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST rmw_fastrtps gives the participant shared
    memory whatever FASTDDS_BUILTIN_TRANSPORTS says (a plain participant listens on it); a
    node's participant (stall_safe_transports: the UDP profile) does not, nor with SUBNET."""
    assert listens_on_shared_memory('plain', 'LOCALHOST')
    assert not listens_on_shared_memory('node', 'LOCALHOST')
    assert not listens_on_shared_memory('node', 'SUBNET')


def test_an_invalid_handle_from_the_executor_is_skipped_unless_it_never_ends(monkeypatch):
    """rclpy's EventsExecutor can dispatch a QoS event of a subscription destroyed meanwhile
    (InvalidHandle; ros2/rclpy#1644): the node goes on; an endless series still fails."""
    from rclpy._rclpy_pybind11 import InvalidHandle

    class Executor:
        def __init__(self, failures):
            self.failures, self.spins = failures, 0

        def add_node(self, node):
            pass

        def spin_once(self, timeout_sec):
            self.spins += 1
            if self.spins <= self.failures:
                raise InvalidHandle('cannot use Destroyable because destruction was requested')

    class Node:
        exit_code = 0

        def destroy_node(self):
            pass

    monkeypatch.setattr(runner, 'init_or_error', lambda args: None)
    monkeypatch.setattr(runner.rclpy, 'ok', lambda: True)
    for failures, survives in ((3, True), (runner.MAX_INVALID_HANDLES + 1, False)):
        executor = Executor(failures)
        monkeypatch.setattr(runner, 'make_executor', lambda: executor)
        spun = lambda node: executor.spins > failures + 2  # noqa: E731
        if survives:
            assert runner.run(Node, [], done=spun) == 0
        else:
            try:
                runner.run(Node, [], done=spun)
            except InvalidHandle:
                pass
            else:
                raise AssertionError('an endless series of InvalidHandle was skipped')


def test_a_node_that_refuses_to_start_ends_its_process_before_it_is_destroyed(monkeypatch):
    """A node refusing to start after ``Node.__init__`` made its participant: its process ends
    (exit 2, one ``error:`` line) while the exception still holds the half-built node -- its
    participant's destruction could deadlock Fast DDS amid peers coming and going (runner.refuse).
    A test calling ``run`` in its own process gets 2 back."""
    from vib_estimator.errors import StartupError

    made = []

    class Refusing:
        def __init__(self):
            made.append(weakref.ref(self))
            raise StartupError('parameter bag is required')

    class Ended(Exception):
        pass

    def end_process(code):
        raise Ended(code, made[-1]() is not None)

    monkeypatch.setattr(runner, 'init_or_error', lambda args: None)
    monkeypatch.setattr(runner, 'end_process', end_process)
    monkeypatch.setattr(runner, 'runs_a_node', lambda: True)
    try:
        runner.run(Refusing, [])
    except Ended as ended:
        assert ended.args == (2, True)
    else:
        raise AssertionError('the process of a node refusing to start was not ended')
    monkeypatch.setattr(runner, 'runs_a_node', lambda: False)
    assert runner.run(Refusing, []) == 2
    assert made[-1]() is None


def test_a_node_module_run_with_python_m_runs_a_node(monkeypatch):
    """``python -m vib_estimator.nodes.<module>`` is a node's process; pytest's, or ``python -c``,
    is not."""
    from types import SimpleNamespace

    from vib_estimator.nodes import stopping

    assert not stopping.runs_a_node()
    code = 'from vib_estimator.nodes import stopping; print(stopping.runs_a_node())'
    plain = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True)
    assert plain.stdout.split() == ['False'], plain.stderr
    node_main = SimpleNamespace(__spec__=SimpleNamespace(name='vib_estimator.nodes.bag_replayer'))
    monkeypatch.setitem(sys.modules, '__main__', node_main)
    assert stopping.runs_a_node()
