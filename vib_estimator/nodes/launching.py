# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""What the launch files in ``launch/`` share, without launch or launch_ros (so it is tested
where they are not installed): the package's parameters files, the arguments several files
declare, a value a parameters file sets, and the arguments given over a file's settings."""

from __future__ import annotations

import os
from typing import Callable, Dict, Iterable, Optional, Tuple

import yaml
from ament_index_python import packages

PACKAGE = 'vib_estimator'
#: the launch arguments several launch files declare: name -> (default, description)
COMMON_ARGUMENTS: Dict[str, Tuple[str, str]] = {
    'namespace': ('', 'namespace of the nodes, their topics and services'),
    'use_sim_time': ('false', 'true: time from /clock'),
    'input_type': ('', "estimator input message type (empty: the file's)"),
    'input_topic': ('', "estimator input topic (empty: the file's)"),
}
#: estimator_node's input arguments: empty leaves its parameters file's setting in place
INPUT_ARGUMENTS = ('input_type', 'input_topic')


def config_file(name: str) -> str:
    """A parameters file of the installed package (share/vib_estimator/config)."""
    return os.path.join(packages.get_package_share_directory(PACKAGE), 'config', name)


def params_file_argument(prefix: str, executable: str) -> Tuple[str, Tuple[str, str]]:
    """The launch argument ``<prefix>_params_file`` of ``executable``: its name, default
    (config/``<prefix>``.yaml) and description."""
    return f'{prefix}_params_file', (
        config_file(f'{prefix}.yaml'),
        f'parameters file of {executable}',
    )


def file_parameter(path: str, name: str):
    """The value a parameters file gives ``name`` (under any node key), or None."""
    with open(path) as f:
        data = yaml.safe_load(f) or {}
    values = [
        section.get('ros__parameters', {}).get(name)
        for section in data.values()
        if isinstance(section, dict)
    ]
    return next((v for v in values if v is not None), None)


def given(
    value: Callable[[str], str], names: Iterable[str], convert: Optional[Callable] = None
) -> dict:
    """The arguments among ``names`` given a non-empty value (``value(name)``, a launch
    argument's text), converted: the parameters they override in a node's file."""
    found = {name: value(name) for name in names}
    return {name: convert(text) if convert else text for name, text in found.items() if text}


def truthy(text) -> bool:
    """A launch argument's or a parameters file's boolean (``true``/``True``/True)."""
    return str(text).lower() == 'true'


def node_action(node_class, executable: str, namespace, parameters):
    """A ``launch_ros.actions.Node`` (``node_class``: this module imports no launch package) of
    this package's ``executable``, named after it, output on the screen."""
    return node_class(
        package=PACKAGE,
        executable=executable,
        name=executable,
        namespace=namespace,
        parameters=parameters,
        output='screen',
        emulate_tty=True,
    )
