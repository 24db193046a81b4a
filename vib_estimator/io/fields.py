# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The input message types, their scalar fields (``component``), and the stamp time base.

No rclpy import: the functions only use attribute access, which both rclpy's generated classes and
rosbags' deserialised dataclasses provide, so the node, the replayer and the offline readers share
one definition of what a component is.

Supported types (full names, as in ``input_type``) and their components:

* ``geometry_msgs/msg/WrenchStamped``  -- ``force.x|y|z``, ``torque.x|y|z``
* ``sensor_msgs/msg/Imu``              -- ``linear_acceleration.x|y|z``, ``angular_velocity.x|y|z``
* ``geometry_msgs/msg/AccelStamped``   -- ``accel.linear.x|y|z``, ``accel.angular.x|y|z``
* ``geometry_msgs/msg/Vector3Stamped`` -- ``vector.x|y|z``
* ``sensor_msgs/msg/JointState``       -- ``effort[NAME]``, ``position[NAME]``, ``velocity[NAME]``
  (the joint is looked up by name in every message; a message without it gives ``None``)
* ``std_msgs/msg/Float64``             -- ``data``
* ``std_msgs/msg/Float32``             -- ``data`` (a microcontroller's sensor, micro-ROS)
  (no header, either: the receiver's clock is the time base)
"""

from __future__ import annotations

import re
from operator import attrgetter
from typing import Callable, Dict, Optional, Sequence, Tuple

WRENCH_STAMPED = 'geometry_msgs/msg/WrenchStamped'
#: the topic estimator_node reads by default (and ``analyze`` picks in a bag of several inputs)
DEFAULT_INPUT_TOPIC = 'coupling_torque'
IMU = 'sensor_msgs/msg/Imu'
ACCEL_STAMPED = 'geometry_msgs/msg/AccelStamped'
VECTOR3_STAMPED = 'geometry_msgs/msg/Vector3Stamped'
JOINT_STATE = 'sensor_msgs/msg/JointState'
FLOAT64 = 'std_msgs/msg/Float64'
FLOAT32 = 'std_msgs/msg/Float32'
#: the types without a header (each sample stamped with its receipt time, or in a bag its log time)
HEADERLESS = (FLOAT64, FLOAT32)

#: the axes of a Vector3, in order
XYZ = ('x', 'y', 'z')
#: fixed components of each type, as attribute paths from the message
_FIXED: Dict[str, Tuple[str, ...]] = {
    WRENCH_STAMPED: tuple(f'{v}.{a}' for v in ('force', 'torque') for a in XYZ),
    IMU: tuple(f'{v}.{a}' for v in ('linear_acceleration', 'angular_velocity') for a in XYZ),
    ACCEL_STAMPED: tuple(f'accel.{v}.{a}' for v in ('linear', 'angular') for a in XYZ),
    VECTOR3_STAMPED: tuple(f'vector.{a}' for a in XYZ),
    JOINT_STATE: (),
    FLOAT64: ('data',),
    FLOAT32: ('data',),
}
#: every supported input type, default first
INPUT_TYPES: Tuple[str, ...] = tuple(_FIXED)
#: default component of each type
DEFAULT_COMPONENT = {
    WRENCH_STAMPED: 'torque.z',
    IMU: 'linear_acceleration.z',
    ACCEL_STAMPED: 'accel.linear.z',
    VECTOR3_STAMPED: 'vector.z',
    JOINT_STATE: 'effort[joint1]',
    FLOAT64: 'data',
    FLOAT32: 'data',
}
#: the components of a WrenchStamped (the default input type)
COMPONENTS = _FIXED[WRENCH_STAMPED]
_JOINT = re.compile(r'^(effort|position|velocity)\[(.+)\]$')


def normalise_type(name: str) -> str:
    """``pkg/Name`` (older bags, ROS 1 style) as ``pkg/msg/Name``; other names unchanged."""
    parts = name.split('/')
    return f'{parts[0]}/msg/{parts[1]}' if len(parts) == 2 else name


def check_input_type(input_type: str) -> str:
    """The full type name if it is a supported input type, else ``ValueError`` listing them."""
    full = normalise_type(input_type)
    if full not in _FIXED:
        raise ValueError(f'input_type must be one of {", ".join(INPUT_TYPES)}, got {input_type!r}')
    return full


def has_header(input_type: str) -> bool:
    """Whether messages of this type carry a ``std_msgs/Header`` (time base: its stamp)."""
    return check_input_type(input_type) not in HEADERLESS


def describe_components(input_type: str) -> str:
    """The components of a type, as a phrase for help texts and error messages."""
    full = check_input_type(input_type)
    if full == JOINT_STATE:
        return 'effort[NAME], position[NAME] or velocity[NAME] (NAME: a joint name)'
    return ', '.join(_FIXED[full])


def check_component(component: str, input_type: str = WRENCH_STAMPED) -> str:
    """Return ``component`` if it names a field of ``input_type``, else raise ``ValueError``."""
    full = check_input_type(input_type)
    ok = _JOINT.match(component) is not None if full == JOINT_STATE else component in _FIXED[full]
    if not ok:
        raise ValueError(
            f'component of {full} must be one of {describe_components(full)}, got {component!r}'
        )
    return component


def component_getter(
    component: str, input_type: str = WRENCH_STAMPED
) -> Callable[[object], Optional[float]]:
    """A function returning ``component`` of a message of ``input_type``.

    Fixed fields are one ``operator.attrgetter`` (one C call per message). For ``JointState`` the
    joint is found by name in each message (publishers may reorder or omit joints); the function
    returns ``None`` when the message lacks it, or lacks that array's entry.
    """
    full = check_input_type(input_type)
    check_component(component, full)
    if full == WRENCH_STAMPED:
        return attrgetter('wrench.' + component)
    if full != JOINT_STATE:
        return attrgetter(component)
    field, joint = _JOINT.match(component).groups()
    values_of = attrgetter(field)

    def joint_value(msg) -> Optional[float]:
        try:
            i = list(msg.name).index(joint)
            return float(values_of(msg)[i])
        except (ValueError, IndexError):
            return None

    return joint_value


def check_components(components, input_type: str = WRENCH_STAMPED) -> Tuple[str, ...]:
    """``components`` (several fields of one message, one channel each) checked: each a component
    of ``input_type`` (:func:`check_component`), none given twice, none with a comma (the outputs
    join the channel names with commas); ``ValueError`` otherwise."""
    out: list = []
    for component in components:
        check_component(component, input_type)
        if ',' in component:
            raise ValueError(
                f'component {component!r} has a comma (channel names are joined by one)'
            )
        if component in out:
            raise ValueError(f'component {component!r} is given twice in components')
        out.append(component)
    return tuple(out)


def channels_of(component: str, components, input_type: str = WRENCH_STAMPED) -> Tuple[str, ...]:
    """The channels a reader takes: ``components`` (checked) if any, else ``(component,)``."""
    if components:
        return check_components(components, input_type)
    return (check_component(component, input_type),)


def topic_channels(topics: Sequence[str], fields: Tuple[str, ...]) -> Tuple[str, ...]:
    """The channel names of ``fields`` read from each of ``topics``: the fields themselves for one
    topic, ``topic:field`` for each topic and field (topic by topic) for several."""
    if len(topics) < 2:
        return tuple(fields)
    return tuple(f'{topic}:{field}' for topic in topics for field in fields)


def channels_getter(
    channels: Tuple[str, ...], input_type: str = WRENCH_STAMPED
) -> Callable[[object], Optional[object]]:
    """A function returning the ``channels`` of a message: one channel, its value
    (:func:`component_getter`, unchanged); several, the tuple of their values (fixed fields: one
    ``operator.attrgetter``), or ``None`` when a ``JointState`` message lacks one of the joints."""
    full = check_input_type(input_type)
    check_components(channels, full)
    if len(channels) == 1:
        return component_getter(channels[0], full)
    if full != JOINT_STATE:
        prefix = 'wrench.' if full == WRENCH_STAMPED else ''
        return attrgetter(*(prefix + c for c in channels))
    getters = [component_getter(c, full) for c in channels]

    def joint_values(msg) -> Optional[tuple]:
        values = tuple(get(msg) for get in getters)
        return None if None in values else values

    return joint_values


def component_setter(
    component: str, input_type: str = WRENCH_STAMPED
) -> Callable[[object, float], None]:
    """The inverse of :func:`component_getter`: a function ``set(msg, value)`` writing ``value``
    into ``component`` of a message of ``input_type`` (for publishers: the simulator, tests,
    benchmarks). For ``JointState`` the joint is appended to ``name`` when the message lacks it
    and the array is extended to the names (with 0.0) when shorter."""
    full = check_input_type(input_type)
    check_component(component, full)
    if full != JOINT_STATE:
        *path, last = (('wrench.' if full == WRENCH_STAMPED else '') + component).split('.')
        parent = attrgetter('.'.join(path)) if path else (lambda msg: msg)

        def set_field(msg, value: float) -> None:
            setattr(parent(msg), last, float(value))

        return set_field
    field, joint = _JOINT.match(component).groups()

    def set_joint(msg, value: float) -> None:
        names = list(msg.name)
        if joint not in names:
            names.append(joint)
            msg.name = names
        values = list(getattr(msg, field))
        values += [0.0] * (len(names) - len(values))
        values[names.index(joint)] = float(value)
        setattr(msg, field, values)

    return set_joint


def stamp_ns(header) -> int:
    """A ``std_msgs/Header`` stamp as integer nanoseconds (exact)."""
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def seconds_since(stamp: int, origin: int) -> float:
    """Stamp relative to an origin, both integer ns, as float seconds.

    The estimator's time base. Subtracting in integers first keeps the full resolution of the
    stamps (an epoch time in float seconds has only ~0.2 us resolution), and the node and the
    offline ``analyze`` command both use this function so that they see the same floats.
    """
    return (stamp - origin) * 1e-9


#: unit of each field (the last attribute before the axis, or the JointState array), SI as
#: the ROS message definitions (REP 103) give them
FIELD_UNITS = {
    'force': 'N',
    'torque': 'N·m',
    'linear_acceleration': 'm/s²',
    'angular_velocity': 'rad/s',
    'linear': 'm/s²',
    'angular': 'rad/s²',
    'effort': 'N·m or N',
    'position': 'rad or m',
    'velocity': 'rad/s or m/s',
}
#: units spelled as a name's last ``_``-separated tokens (``accel_g``, ``tip_velocity_m_s``)
SUFFIX_UNITS = {
    ('m', 's2'): 'm/s²',
    ('rad', 's'): 'rad/s',
    ('m', 's'): 'm/s',
    ('rad',): 'rad',
    ('deg',): 'deg',
    ('m',): 'm',
    ('mm',): 'mm',
    ('g',): 'g',
    ('n',): 'N',
    ('nm',): 'N·m',
    ('v',): 'V',
    ('a',): 'A',
    ('pa',): 'Pa',
}
#: the unit of a signal whose name says none
UNKNOWN_UNIT = 'signal units'
_BRACKETED = re.compile(r'[\(\[]\s*([^\)\]]+?)\s*[\)\]]\s*$')


def signal_unit(name: str) -> str:
    """The unit of a signal named ``name``: a component (``torque.z``, ``effort[joint1]``), or a
    CSV column that carries its unit in brackets (``torque (N·m)``, ``acc [g]``) or as its last
    tokens (``accel_g``, ``tip_velocity_m_s``); :data:`UNKNOWN_UNIT` otherwise."""
    name = name.strip()
    joint = _JOINT.match(name)
    if joint:
        return FIELD_UNITS[joint.group(1)]
    bracketed = _BRACKETED.search(name)
    if bracketed:
        return bracketed.group(1)
    parts = name.split('.')
    if len(parts) >= 2 and parts[-1] in XYZ and parts[-2] in FIELD_UNITS:
        return FIELD_UNITS[parts[-2]]
    if name in FIELD_UNITS:
        return FIELD_UNITS[name]
    tokens = tuple(name.lower().split('_'))
    for suffix in sorted(SUFFIX_UNITS, key=len, reverse=True):
        if len(tokens) > len(suffix) and tokens[-len(suffix) :] == suffix:
            return SUFFIX_UNITS[suffix]
    return UNKNOWN_UNIT
