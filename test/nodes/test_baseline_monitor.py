# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""estimator_node with a learned baseline: the covariate topic found in the graph, the compensated
change published, an alarm (and a diagnostics ERROR naming the mode) on a window whose frequency
left the baseline, none on a normal one; learning on line through ~/learn_baseline."""

import numpy as np
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import Temperature
from std_msgs.msg import Bool, Float64
from std_srvs.srv import SetBool

from vib_estimator.core import health_model as hm
from vib_estimator.io import fields
from vib_estimator.nodes.estimator_node import EstimatorNode, message_class
from vib_estimator.nodes.runner import spin_until, spin_until_arrival

EPOCH_NS = 10**18
FS = 250.0
WINDOW_S = 2.0


def f_of(celsius):
    return 5.0 * (1 - 0.002 * celsius)


def saved_baseline(path):
    rng = np.random.default_rng(0)
    x = rng.uniform(-10, 10, 30)
    f = f_of(x) + 0.02 * rng.standard_normal(30)
    mode = hm.fit_mode('/coupling_torque', 'torque.z', 1, f, x)
    hm.save(hm.Baseline(['/temperature:temperature'], [mode]), path)


class Probe:
    def __init__(self, context, executor, node):
        self.executor, self.node = executor, node
        self.probe = Node('probe', context=context)
        self.torque = self.probe.create_publisher(
            message_class(fields.WRENCH_STAMPED), 'coupling_torque', 1000
        )
        self.temperature = self.probe.create_publisher(Temperature, '/temperature', 10)
        self.alarms, self.changes, self.diagnostics = [], [], []
        subs = [
            self.probe.create_subscription(Bool, 'vibration/alarm', self.alarms.append, 10),
            self.probe.create_subscription(
                Float64, 'vibration/mode1/change', lambda m: self.changes.append(m.data), 1000
            ),
            self.probe.create_subscription(
                DiagnosticArray, '/diagnostics', self.diagnostics.append, 10
            ),
        ]
        self.learn = self.probe.create_client(SetBool, 'estimator_node/learn_baseline')
        executor.add_node(node)
        executor.add_node(self.probe)
        assert spin_until(
            executor,
            lambda: (
                self.torque.get_subscription_count() >= 1
                and self.temperature.get_subscription_count() >= 1
                and subs[0].get_publisher_count() >= 1
                and subs[2].get_publisher_count() >= 1
                and self.learn.service_is_ready()
            ),
            10.0,
        )
        self.sample, self.phase, self.sent = 0, 0.0, 0

    def window(self, frequency, celsius, seconds=WINDOW_S):
        """``seconds`` of a sine of ``frequency`` (phase-continuous) while the temperature is
        ``celsius`` (sent first, and taken before the samples)."""
        msg = Temperature(temperature=float(celsius))
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(self.stamp(), 10**9)
        self.temperature.publish(msg)
        received = self.node.baseline_monitor.received
        assert spin_until(
            self.executor, lambda: self.node.baseline_monitor.received > received, 5.0
        )
        for _ in range(int(seconds * FS)):
            msg = message_class(fields.WRENCH_STAMPED)()
            stamp = self.stamp()
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp, 10**9)
            self.phase += 2 * np.pi * frequency / FS
            msg.wrench.torque.z = float(np.sin(self.phase))
            self.torque.publish(msg)
            self.sample += 1
            self.sent += 1
            if self.sent % 50 == 0:
                self.taken()
        self.taken()

    def stamp(self):
        return EPOCH_NS + round(self.sample * 1e9 / FS)

    def taken(self):
        assert spin_until(self.executor, lambda: self.node.counters['received'] >= self.sent, 10.0)


def make(ros_context, executor, path, **extra):
    params = {'baseline_file': str(path), 'health_window_s': WINDOW_S, **extra}
    node = EstimatorNode(
        context=ros_context,
        parameter_overrides=[Parameter(k, value=v) for k, v in params.items()],
    )
    return Probe(ros_context, executor, node)


def test_alarm_on_a_changed_window_only(ros_context, executor, tmp_path):
    saved_baseline(tmp_path / 'b.yaml')
    p = make(ros_context, executor, tmp_path / 'b.yaml')
    p.window(f_of(8.0), 8.0)  # normal, warm
    p.window(f_of(-6.0) * 0.94, -6.0)  # 6 % below the baseline's prediction
    p.window(f_of(0.0), 0.0, 1.0)  # opens the next window: the previous one is judged
    assert [a.data for a in p.alarms] == [False, True]
    assert min(p.changes) < -0.04
    status = spin_until_arrival(
        p.executor, p.diagnostics, lambda a: a.status[0].level == DiagnosticStatus.ERROR, 5.0
    ).status[0]
    assert 'mode 1' in status.message and 'beyond the baseline' in status.message


def test_learn_baseline_on_line(ros_context, executor, tmp_path):
    path = tmp_path / 'learned.yaml'
    p = make(ros_context, executor, path, covariate_topics='/temperature:temperature')
    future = p.learn.call_async(SetBool.Request(data=True))
    assert spin_until(executor, future.done, 5.0) and future.result().success
    for celsius in (-8.0, -3.0, 2.0, 6.0, 9.0):
        p.window(f_of(celsius), celsius)
    future = p.learn.call_async(SetBool.Request(data=False))
    assert spin_until(executor, future.done, 5.0)
    assert future.result().success, future.result().message
    learned = hm.load(path)
    assert learned.covariates == ['/temperature:temperature'] and learned.modes[0].n == 5
    assert learned.modes[0].coef[1] < 0  # the frequency falls as it warms
    p.window(f_of(0.0) * 0.9, 0.0)
    p.window(f_of(0.0), 0.0, 1.0)
    assert p.alarms[-1].data
