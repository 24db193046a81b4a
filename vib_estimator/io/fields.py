"""Field access on ``geometry_msgs/WrenchStamped`` messages, for rclpy and rosbags messages alike.

No rclpy import: the functions only use attribute access, which both rclpy's generated classes and
rosbags' deserialised dataclasses provide.
"""
from __future__ import annotations

from operator import attrgetter
from typing import Callable

COMPONENTS = ('force.x', 'force.y', 'force.z', 'torque.x', 'torque.y', 'torque.z')


def check_component(component: str) -> str:
    """Return ``component`` if it names a Wrench field, else raise ``ValueError`` saying which do."""
    if component not in COMPONENTS:
        raise ValueError(f'component must be one of {", ".join(COMPONENTS)}, got {component!r}')
    return component


def component_getter(component: str) -> Callable[[object], float]:
    """A function returning ``component`` (e.g. ``torque.z``) of a WrenchStamped message.

    Built once (``operator.attrgetter``), so the per-message cost is one C call.
    """
    return attrgetter('wrench.' + check_component(component))


def stamp_ns(header) -> int:
    """A ``std_msgs/Header`` stamp as integer nanoseconds (exact)."""
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def seconds_since(stamp: int, origin: int) -> float:
    """Stamp relative to an origin, both integer ns, as float seconds.

    The estimator's time base. Subtracting in integers first keeps the full resolution of the
    stamps (an epoch time in float seconds has only ~0.2 us resolution), and the node and the offline
    ``analyze`` command both use this function so that they see the same floats.
    """
    return (stamp - origin) * 1e-9
