# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""A node asked to run secured (SROS2: ROS_SECURITY_ENABLE, strategy Enforce, its enclave in a
keystore laid out as ``ros2 security`` makes it) fails closed where the middleware cannot do DDS
security (the PyPI wheels' Fast DDS: docs/security.md): one ``error:`` line, exit 2, neither a
traceback nor rclpy's warning about the rosout publisher of the node that was never made."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ENCLAVE = '/vib_estimator/estimator_node'
#: the files ``ros2 security create_enclave`` writes (empty here: refused before they are read)
FILES = (
    'identity_ca.cert.pem',
    'cert.pem',
    'key.pem',
    'permissions_ca.cert.pem',
    'governance.p7s',
    'permissions.p7s',
)


def test_a_secured_start_the_middleware_cannot_do_is_one_error_line(tmp_path):
    enclave = tmp_path / 'keystore' / 'enclaves' / ENCLAVE.strip('/')
    enclave.mkdir(parents=True)
    for name in FILES:
        (enclave / name).touch()
    env = dict(
        os.environ,
        ROS_SECURITY_ENABLE='true',
        ROS_SECURITY_STRATEGY='Enforce',
        ROS_SECURITY_KEYSTORE=str(tmp_path / 'keystore'),
    )
    exe = Path(sys.executable).parent / 'estimator_node'
    run = subprocess.run(
        [str(exe), '--ros-args', '--enclave', ENCLAVE],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )
    lines = (run.stdout + run.stderr).splitlines()
    assert run.returncode == 2, lines
    errors = [line for line in lines if line.startswith('error:')]
    assert len(errors) == 1, lines
    # rcl's own INFO naming the security directory may come before it; nothing else
    assert all(line in errors or '[INFO]' in line for line in lines), lines
