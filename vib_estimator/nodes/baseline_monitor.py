# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""estimator_node's health monitoring against a learned baseline (the model and the window logic:
:class:`~vib_estimator.core.health_model.LiveHealth`, the same as ``survey``'s; docs/health.md).

Parameters (read-only): ``baseline_file`` (a baseline saved by ``survey --save-baseline`` or by
``~/learn_baseline``; a path that does not exist yet is where learning saves), ``covariate_topics``
(``TOPIC:FIELD,...``; default: the baseline's covariates; each topic's type is taken from the ROS
graph once it appears, any message type with that numeric field), ``health_window_s`` (the
estimates and covariates are averaged over windows of this much stream time, each standing for one
recording of the training; default :data:`DEFAULT_WINDOW_S`).

Outputs: ``vibration/mode<k>/change`` (std_msgs/Float64, the compensated relative change of
baseline mode k over the current window, on each estimate), ``vibration/alarm`` (std_msgs/Bool,
at each window's end: whether a mode is beyond the baseline at its false-alarm probability),
and the diagnostics turn ERROR naming the mode, by how much and since when. Service
``~/learn_baseline`` (std_srvs/SetBool): ``true`` starts learning over a commissioning period,
``false`` ends it, fits the baseline from the windows seen, saves it to ``baseline_file`` and
monitors with it.
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import List

from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from std_msgs.msg import Bool, Float64
from std_srvs.srv import SetBool

from ..analysis.interval import combine
from ..core import health_model as hm
from ..errors import StartupError
from . import health as H
from .parameters import declare, descriptor

#: default window: the 300 s recordings of ``make survey-temperature``
DEFAULT_WINDOW_S = 300.0
#: how often covariate topics not yet subscribed are looked for in the graph, s
DISCOVERY_PERIOD = 0.5


def _covariates():
    """:mod:`..io.covariates`, imported by a node that has covariates: with it come the bag
    readers and their type stores (0.25-0.4 s of every estimator node's start otherwise)."""
    from ..io import covariates

    return covariates


def window_frequency(f, s, t, span) -> float:
    """A window's frequency as ``survey`` summarises a recording (:func:`..interval.combine`)."""
    return combine(f, s, t, span).value


class BaselineMonitor:
    """Declares the parameters, subscribes to the covariates, publishes the changes and alarms."""

    def __init__(self, node: Node, origin=lambda: None) -> None:
        #: ``origin()``: the input's first stamp, ns (None before it)
        self.origin = origin
        self._node = node
        path = declare(
            node,
            'baseline_file',
            '',
            descriptor(
                'learned health baseline (YAML, survey --save-baseline); learning on line '
                'saves here ("" = no monitoring, no learning)',
                read_only=True,
            ),
        )
        spec = declare(
            node,
            'covariate_topics',
            '',
            descriptor("covariates TOPIC:FIELD,... (default: the baseline's)", read_only=True),
        )
        window = declare(
            node,
            'health_window_s',
            DEFAULT_WINDOW_S,
            descriptor(
                'health monitoring window (one recording of the training), s',
                (1.0, 86400.0),
                read_only=True,
            ),
        )
        self.path = Path(path) if path else None
        baseline = None
        try:
            if self.path is not None and self.path.exists():
                baseline = hm.load(self.path)
            covariates = _covariates().parse_covariates(spec) if spec else []
        except ValueError as err:
            raise StartupError(str(err)) from None
        if baseline is not None:
            if covariates and covariates != baseline.covariates:
                raise StartupError(
                    f"covariate_topics {spec} differ from the baseline's "
                    f'({",".join(baseline.covariates)})'
                )
            covariates = list(baseline.covariates)
        if any(not _covariates().split_spec(c)[0] for c in covariates):
            raise StartupError('covariate_topics: each is TOPIC:FIELD')
        self.live = hm.LiveHealth(baseline, covariates, window, summarise=window_frequency)
        self._changes = {}
        self._alarm = node.create_publisher(Bool, 'vibration/alarm', 10)
        self._subscribed: List = [None] * len(covariates)
        self._msg = Float64()
        #: covariate messages taken
        self.received = 0
        node.create_service(SetBool, '~/learn_baseline', self._on_learn)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self._discovery = None
        if covariates:
            self._discovery = node.create_timer(DISCOVERY_PERIOD, self._discover, clock=steady)
            self._discover()

    @property
    def active(self) -> bool:
        return self.path is not None

    # ---- covariates ------------------------------------------------------------------------
    def _discover(self) -> None:
        """Subscribe to each covariate topic once the graph says its type."""
        types = dict(self._node.get_topic_names_and_types())
        for i, spec in enumerate(self.live.covariates):
            if self._subscribed[i] is not None:
                continue
            topic, name = _covariates().split_spec(spec)
            kinds = types.get(self._node.resolve_topic_name(topic))
            if not kinds:
                continue
            package, _, kind = kinds[0].split('/')
            cls = getattr(importlib.import_module(f'{package}.msg'), kind)
            getter = _covariates().field_getter(name)
            self._subscribed[i] = self._node.create_subscription(
                cls,
                topic,
                lambda msg, i=i, getter=getter: self._on_covariate(i, msg, getter),
                qos_profile_sensor_data,
            )
        if all(s is not None for s in self._subscribed):
            self._discovery.cancel()

    def _on_covariate(self, index: int, msg, getter) -> None:
        """A covariate message: its value in the window of its header stamp (stream time of the
        input's first stamp, as the estimates'), else in the current window."""
        t = None
        origin = self.origin()
        header = getattr(msg, 'header', None)
        if (
            origin is not None
            and header is not None
            and (header.stamp.sec or header.stamp.nanosec)
        ):
            t = (header.stamp.sec * 1_000_000_000 + header.stamp.nanosec - origin) * 1e-9
        try:
            value = float(getter(msg))
        except (AttributeError, TypeError, ValueError):
            return
        self.received += 1
        self.live.covariate(index, value, t)

    # ---- estimates -------------------------------------------------------------------------
    def estimate(self, estimate) -> None:
        """An estimate of the node: into the window; its mode's running change; at a window's
        end the alarm."""
        mode = max(estimate.mode, 1)
        closed = self.live.estimate(
            estimate.t,
            mode,
            estimate.frequency_hz,
            estimate.frequency_std_hz,
            estimate.convergence_time,
        )
        if closed is not None and self.live.baseline is not None:
            self._alarm.publish(Bool(data=any(r.alarm for r in closed)))
        running = self.live.running_change(mode)
        if running is not None:
            k, change = running
            if k not in self._changes:
                self._changes[k] = self._node.create_publisher(
                    Float64, f'vibration/mode{k}/change', 10
                )
            self._msg.data = change
            self._changes[k].publish(self._msg)

    def status(self, status: H.Status) -> H.Status:
        """ERROR naming the alarmed modes of the last closed window; the baseline's state in the
        values."""
        values = dict(status.values)
        values['baseline'] = (
            'learning'
            if self.live.learning
            else ('none' if self.live.baseline is None else str(self.path))
        )
        for r in self.live.last:
            values[f'mode{r.mode}_change'] = f'{r.change.change_rel:+.4%}'
        alarmed = [r for r in self.live.last if r.alarm]
        if not alarmed:
            return H.Status(status.level, status.message, values, status.log)
        text = '; '.join(
            f'mode {r.mode} ({r.frequency_hz:.4g} Hz) changed {r.change.change_rel:+.2%} beyond '
            f'the baseline (limit {r.change.limit_rel:.2%}) since t = {r.since:.0f} s'
            for r in alarmed
        )
        return H.Status(H.ERROR, text, values, status.log)

    # ---- learning --------------------------------------------------------------------------
    def _on_learn(self, request, response):
        if self.path is None:
            response.success, response.message = False, 'set baseline_file to learn a baseline'
        elif request.data:
            self.live.start_learning()
            response.success = True
            response.message = (
                f'learning: windows of {self.live.window_s:g} s until ~/learn_baseline false'
            )
        elif not self.live.learning:
            response.success, response.message = False, 'not learning (call with true first)'
        else:
            self.live.close(restart=True)
            try:
                baseline = self.live.learned()
            except ValueError as err:
                response.success, response.message = False, str(err)
                return response
            hm.save(baseline, self.path)
            self.live.baseline = baseline
            response.success = True
            response.message = (
                f'baseline of {len(baseline.modes)} mode(s) from {baseline.trained_on} saved to '
                f'{self.path}'
            )
        self._node.get_logger().info(f'learn_baseline: {response.message}')
        return response
