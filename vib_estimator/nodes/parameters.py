"""Parameter declaration shared by the package's nodes: descriptors with ranges, one place where
a value the node cannot start with becomes a :class:`~vib_estimator.nodes.runner.StartupError`, and
the estimator's parameters (one per :class:`EstimatorConfig` field) declared and read back.
"""
from __future__ import annotations

from typing import Optional, Sequence

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.exceptions import ParameterException
from rclpy.node import Node
from rclpy.parameter import Parameter

from ..core.config import EstimatorConfig
from ..io.fields import (DEFAULT_COMPONENT, DEFAULT_INPUT_TOPIC, INPUT_TYPES, WRENCH_STAMPED,
                         check_input_type, describe_components)
from .runner import StartupError


def descriptor(description: str, bounds: Optional[Sequence] = None, read_only: bool = False,
               **extra) -> ParameterDescriptor:
    """A ParameterDescriptor; ``bounds`` = (lo, hi, ...) adds an integer range when both bounds
    are ints, else a floating-point range (closed: open bounds are the validator's business)."""
    d = ParameterDescriptor(description=description, read_only=read_only, **extra)
    if bounds is not None:
        lo, hi = bounds[0], bounds[1]
        if isinstance(lo, int) and isinstance(hi, int):
            d.integer_range = [IntegerRange(from_value=lo, to_value=hi, step=1)]
        else:
            d.floating_point_range = [FloatingPointRange(from_value=float(lo),
                                                         to_value=float(hi))]
    return d


def declare(node: Node, name: str, default, desc: ParameterDescriptor):
    """Declare a parameter and return its value; a refused override (out of range, wrong type,
    e.g. ``rate:=10`` for a double) raises :class:`StartupError` with rclpy's reason."""
    try:
        return node.declare_parameter(name, default, desc).value
    except ParameterException as err:
        raise StartupError(str(err)) from None


def config_value(value):
    """A ROS parameter value as EstimatorConfig takes it: an empty array (or none) is None."""
    if value is None or (not isinstance(value, str) and hasattr(value, '__len__')
                         and len(value) == 0):
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
            declare(node, name, Parameter.Type.DOUBLE_ARRAY,
                    descriptor(description + ' ([] = off)'))
            if node.get_parameter_or(name).type_ == Parameter.Type.NOT_SET:
                node.set_parameters([Parameter(name, Parameter.Type.DOUBLE_ARRAY, [])])
        else:
            declare(node, name, default, descriptor(description, bounds))


def config_of(node: Node) -> EstimatorConfig:
    """The EstimatorConfig of the node's current parameter values (ValueError if invalid)."""
    return EstimatorConfig().replace(**{name: config_value(node.get_parameter(name).value)
                                        for name in EstimatorConfig.names()})


def declare_input(node: Node, default_topic: str = DEFAULT_INPUT_TOPIC):
    """Declare ``input_type`` and ``input_topic`` (read-only) and ``component`` (its default
    that of the type); return (the type's full name, the topic)."""
    input_type = declare(node, 'input_type', WRENCH_STAMPED, descriptor(
        f'input message type, one of {", ".join(INPUT_TYPES)}', read_only=True))
    try:
        input_type = check_input_type(input_type)
    except ValueError as err:
        raise StartupError(str(err)) from None
    topic = declare(node, 'input_topic', default_topic, descriptor(
        'input topic, of type input_type', read_only=True))
    declare(node, 'component', DEFAULT_COMPONENT[input_type], descriptor(
        f'field of the input to estimate on: {describe_components(input_type)}'))
    return input_type, topic
