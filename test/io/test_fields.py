# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""io/fields.py: types, components, getters and setters, on plain objects (no rclpy)."""

from __future__ import annotations

from types import SimpleNamespace as NS

import pytest

from vib_estimator.io import fields as F


def empty(input_type):
    """A stand-in message of ``input_type`` with the attributes the components name."""
    xyz = lambda: NS(x=0.0, y=0.0, z=0.0)  # noqa: E731
    return {
        F.WRENCH_STAMPED: lambda: NS(wrench=NS(force=xyz(), torque=xyz())),
        F.IMU: lambda: NS(linear_acceleration=xyz(), angular_velocity=xyz()),
        F.ACCEL_STAMPED: lambda: NS(accel=NS(linear=xyz(), angular=xyz())),
        F.VECTOR3_STAMPED: lambda: NS(vector=xyz()),
        F.JOINT_STATE: lambda: NS(name=[], effort=[], position=[], velocity=[]),
        F.FLOAT64: lambda: NS(data=0.0),
        F.FLOAT32: lambda: NS(data=0.0),
    }[input_type]()


@pytest.mark.parametrize('input_type', F.INPUT_TYPES)
def test_setter_and_getter_round_trip_every_component(input_type):
    components = F._FIXED[input_type] or ('effort[a]', 'position[b]', 'velocity[a]')
    msg = empty(input_type)
    for i, component in enumerate(components):
        F.component_setter(component, input_type)(msg, i + 0.5)
    for i, component in enumerate(components):
        assert F.component_getter(component, input_type)(msg) == i + 0.5, component
    assert F.DEFAULT_COMPONENT[input_type] in components or input_type == F.JOINT_STATE


def test_joint_state_by_name_reordered_and_absent():
    get = F.component_getter('effort[elbow]', F.JOINT_STATE)
    assert get(NS(name=['elbow', 'wrist'], effort=[1.0, 2.0])) == 1.0
    assert get(NS(name=['wrist', 'elbow'], effort=[1.0, 2.0])) == 2.0
    assert get(NS(name=['wrist'], effort=[1.0])) is None
    assert get(NS(name=['wrist', 'elbow'], effort=[1.0])) is None  # array shorter than names
    msg = NS(name=['wrist'], effort=[3.0], position=[])
    F.component_setter('effort[elbow]', F.JOINT_STATE)(msg, 4.0)
    assert msg.name == ['wrist', 'elbow'] and msg.effort == [3.0, 4.0]


def test_types_and_components_are_checked():
    assert F.check_input_type('sensor_msgs/Imu') == F.IMU
    with pytest.raises(ValueError, match='input_type must be one of'):
        F.check_input_type('sensor_msgs/msg/Image')
    with pytest.raises(ValueError, match='component of sensor_msgs/msg/Imu'):
        F.component_setter('torque.z', F.IMU)
    with pytest.raises(ValueError, match=r'effort\[NAME\]'):
        F.check_component('effort', F.JOINT_STATE)
    assert not F.has_header(F.FLOAT64) and F.has_header(F.JOINT_STATE)
    assert not F.has_header(F.FLOAT32)
