# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The nodes' one main (nodes/runner.py): the transports a node's participant talks over. Shared
memory left a node deaf for good after a stall of its own (docs/nodes.md#never-deaf): the nodes
talk UDP unless the user chose (the stall itself: test_soak.py)."""

from __future__ import annotations

from vib_estimator.nodes import runner


def test_a_node_talks_udp_unless_the_user_chose_its_transports():
    environ = {}
    assert runner.stall_safe_transports(environ)
    assert environ == {'FASTDDS_BUILTIN_TRANSPORTS': 'UDPv4'}
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
