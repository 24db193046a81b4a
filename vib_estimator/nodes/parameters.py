"""Parameter declaration shared by the package's nodes: descriptors with ranges, and one place
where a value the node cannot start with becomes a :class:`~vib_estimator.nodes.runner.StartupError`.
"""
from __future__ import annotations

from typing import Optional, Sequence

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.exceptions import ParameterException
from rclpy.node import Node

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
