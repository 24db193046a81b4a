# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Parameter declaration shared by the package's nodes: descriptors with ranges, one place where
a value the node cannot start with becomes a :class:`~vib_estimator.nodes.runner.StartupError`, and
the estimator's parameters (one per :class:`EstimatorConfig` field) declared and read back.
"""

from __future__ import annotations

import sys
from typing import Iterable, List, Optional, Sequence, Tuple

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.exceptions import ParameterException
from rclpy.node import Node
from rclpy.parameter import Parameter

from ..core.config import EstimatorConfig
from ..errors import StartupError
from ..io.align import ALIGN_TOLERANCE_S
from ..io.fields import (
    DEFAULT_COMPONENT,
    DEFAULT_INPUT_TOPIC,
    INPUT_TYPES,
    WRENCH_STAMPED,
    check_input_type,
    describe_components,
    has_header,
)


def descriptor(
    description: str, bounds: Optional[Sequence] = None, read_only: bool = False, **extra
) -> ParameterDescriptor:
    """A ParameterDescriptor; ``bounds`` = (lo, hi, ...) adds an integer range when both bounds
    are ints, else a floating-point range (closed: open bounds are the validator's business)."""
    d = ParameterDescriptor(description=description, read_only=read_only, **extra)
    if bounds is not None:
        lo, hi = bounds[0], bounds[1]
        if isinstance(lo, int) and isinstance(hi, int):
            d.integer_range = [IntegerRange(from_value=lo, to_value=hi, step=1)]
        else:
            d.floating_point_range = [FloatingPointRange(from_value=float(lo), to_value=float(hi))]
    return d


def declare(node: Node, name: str, default, desc: ParameterDescriptor):
    """Declare a parameter and return its value; a refused override (out of range, wrong type,
    e.g. ``rate:=10`` for a double, or ``[]`` for an array with a default) raises
    :class:`StartupError` with rclpy's reason."""
    try:
        value = node.declare_parameter(name, default, desc).value
    except ParameterException as err:
        raise StartupError(str(err)) from None
    if value is None and not isinstance(default, Parameter.Type):
        # an override of [] has no type: rclpy leaves the parameter unset, and reading it raises
        raise StartupError(f'parameter {name} must not be empty (got []); default: {default!r}')
    return value


def config_value(value):
    """A ROS parameter value as EstimatorConfig takes it: an empty array (or none) is None."""
    if value is None or (
        not isinstance(value, str) and hasattr(value, '__len__') and len(value) == 0
    ):
        return None
    return value


def declare_config(node: Node) -> None:
    """Declare one parameter per :class:`EstimatorConfig` field, typed by its default, with the
    field's description and range."""
    defaults = EstimatorConfig()
    for name in EstimatorConfig.names():
        description, bounds = EstimatorConfig.describe(name)
        default = getattr(defaults, name)
        if default is None:
            # an optional array, off by default: rclpy cannot infer a type from [], so declare
            # the type and store an empty array unless an override set a value
            declare(
                node, name, Parameter.Type.DOUBLE_ARRAY, descriptor(description + ' ([] = off)')
            )
            if node.get_parameter_or(name).type_ == Parameter.Type.NOT_SET:
                node.set_parameters([Parameter(name, Parameter.Type.DOUBLE_ARRAY, [])])
        else:
            declare(node, name, default, descriptor(description, bounds))


def config_of(node: Node) -> EstimatorConfig:
    """The EstimatorConfig of the node's current parameter values (ValueError if invalid)."""
    return EstimatorConfig().replace(
        **{name: config_value(node.get_parameter(name).value) for name in EstimatorConfig.names()}
    )


def declare_input(node: Node, default_topic: str = DEFAULT_INPUT_TOPIC):
    """Declare ``input_type``, ``input_topic``, ``input_topics`` and ``sync_tolerance_s``
    (read-only), ``component`` (its default that of the type) and ``components`` (default ``[]``:
    ``component`` alone); return (the type's full name, the topics: ``input_topics`` when it names
    two or more, else ``(input_topic,)``, the stamp tolerance in s)."""
    input_type = declare(
        node,
        'input_type',
        WRENCH_STAMPED,
        descriptor(f'input message type, one of {", ".join(INPUT_TYPES)}', read_only=True),
    )
    try:
        input_type = check_input_type(input_type)
    except ValueError as err:
        raise StartupError(str(err)) from None
    topic = declare(
        node,
        'input_topic',
        default_topic,
        descriptor('input topic, of type input_type', read_only=True),
    )
    topics = declare_array(
        node,
        'input_topics',
        descriptor(
            "several input topics of type input_type, aligned by header stamp: each topic's "
            'component (or components) are its channels, named topic:field, identified jointly '
            '([] = input_topic alone)',
            read_only=True,
        ),
    )
    tolerance = declare(
        node,
        'sync_tolerance_s',
        ALIGN_TOLERANCE_S,
        descriptor(
            'with input_topics: the samples of the topics whose stamps lie within this of each '
            'other are one joint sample, s',
            (0.0, 1.0),
            read_only=True,
        ),
    )
    if len(set(topics)) != len(topics) or any(not t for t in topics):
        raise StartupError(f'input_topics must name distinct topics, got {list(topics)}')
    if len(topics) >= 2 and not has_header(input_type):
        raise StartupError(
            f'input_topics needs a stamped input_type (its samples are aligned by header '
            f'stamp): {input_type} has no header'
        )
    declare(
        node,
        'component',
        DEFAULT_COMPONENT[input_type],
        descriptor(f'field of the input to estimate on: {describe_components(input_type)}'),
    )
    declare_array(
        node,
        'components',
        descriptor(
            'several fields of the input, one channel each, identified jointly with their mode '
            'shapes (excitation free or ambient; [] = component alone): '
            + describe_components(input_type)
        ),
    )
    return input_type, (tuple(topics) if len(topics) >= 2 else (topic,)), tolerance


def declare_array(node: Node, name: str, desc: ParameterDescriptor) -> Tuple[str, ...]:
    """Declare a string-array parameter whose default is ``[]``; return its value (a writable
    one left unset is set to ``[]``, so that it reads as an array)."""
    declare(node, name, Parameter.Type.STRING_ARRAY, desc)
    if node.get_parameter_or(name).type_ == Parameter.Type.NOT_SET:
        if desc.read_only:
            return ()
        node.set_parameters([Parameter(name, Parameter.Type.STRING_ARRAY, [])])
    return tuple(node.get_parameter(name).value)


def params_files(args: Optional[Sequence[str]]) -> List[str]:
    """The ``--params-file`` paths of a command line's ``--ros-args`` sections."""
    files, ros, tokens = [], False, list(args or ())
    for i, token in enumerate(tokens):
        if token == '--ros-args':
            ros = True
        elif token == '--':
            ros = False
        elif ros and token == '--params-file' and i + 1 < len(tokens):
            files.append(tokens[i + 1])
    return files


def _key_matches(pattern: str, name: str) -> bool:
    """rcl's match of a params file's node key (``*`` one token, ``**`` any number of tokens)
    against a fully qualified node name."""
    pat = [p for p in pattern.split('/') if p]
    parts = [p for p in name.split('/') if p]

    def match(i: int, j: int) -> bool:
        if i == len(pat):
            return j == len(parts)
        if pat[i] == '**':
            return any(match(i + 1, k) for k in range(j, len(parts) + 1))
        return j < len(parts) and pat[i] in ('*', parts[j]) and match(i + 1, j + 1)

    return match(0, 0)


def _node_sections(data, prefix: str = '') -> Iterable[Tuple[str, dict]]:
    """(node key, ros__parameters) of a params file's mapping, nested namespaces joined."""
    if not isinstance(data, dict):
        return
    for key, value in data.items():
        if not isinstance(value, dict):
            continue
        path = f'{prefix}/{str(key).strip("/")}'
        if isinstance(value.get('ros__parameters'), dict):
            yield path, value['ros__parameters']
        yield from _node_sections({k: v for k, v in value.items() if k != 'ros__parameters'}, path)


def params_file_warnings(
    files: Sequence[str], node_name: str, declared: Iterable[str]
) -> List[str]:
    """A warning per params file that sets nothing this node (fully qualified ``node_name``,
    parameters ``declared``) has: no key matches the node, or only unknown names do."""
    import yaml

    warnings, declared = [], set(declared)
    for path in files:
        try:
            with open(path) as f:
                sections = list(_node_sections(yaml.safe_load(f)))
        except (OSError, yaml.YAMLError):
            continue  # rcl has already refused such a file
        keys = [key for key, _ in sections]
        names = {n for key, params in sections if _key_matches(key, node_name) for n in params}
        if not names:
            warnings.append(
                f'params file {path} sets nothing for {node_name} (its node keys: '
                f'{", ".join(keys) or "none"}); key it "/**:" to apply it under any '
                'name and namespace'
            )
        elif not names & declared:
            warnings.append(
                f'params file {path} sets only parameters {node_name} does not '
                f'have: {", ".join(sorted(names))}'
            )
    return warnings


def warn_unused_params_files(node: Node, cli_args: Optional[Sequence[str]] = None) -> List[str]:
    """Log (WARN) :func:`params_file_warnings` for the process's command line and the node's
    ``cli_args``; return them."""
    files = params_files(sys.argv) + params_files(cli_args)
    names = node.list_parameters([], 0).names
    warnings = params_file_warnings(files, node.get_fully_qualified_name(), names)
    for text in warnings:
        node.get_logger().warn(text)
    return warnings
