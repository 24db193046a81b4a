#!/usr/bin/env python3
# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Regenerate the simulated recordings in ``bags/`` (deterministic: seeded, no wall-clock time).

    python scripts/make_bags.py [--out bags] [--seed 0]

Writes three rosbag2 directories with MCAP storage (see ``bags/README.md``):

* ``arm_5_3``  -- Section 5.3 / Fig. 5: :func:`vib_estimator.sim.arm_model.experiment_5_3`;
* ``arm_5_5``  -- Section 5.5 / Fig. 7: :func:`vib_estimator.sim.arm_model.experiment_5_5`;
* ``fig1``     -- Section 4 / Fig. 1: :func:`vib_estimator.sim.signals.fig1_signal`.

Each holds ``/coupling_torque`` (``geometry_msgs/msg/WrenchStamped``, the signal in ``torque.z``,
frame ``arm_base``) and ``/vibration/ground_truth`` (``std_msgs/msg/Float64``, the true natural
frequency in Hz, every :data:`TRUTH_EVERY` samples). Header stamps and log times are the simulated
sample times from :data:`EPOCH_NS` (an epoch, not 0, because ROS treats a zero ``/clock`` as "no
time yet"). The bag directories of these names in ``--out`` are replaced.
"""

from __future__ import annotations

import argparse
import math
import shutil
from pathlib import Path

import numpy as np

from vib_estimator.io.bags import TYPESTORE, WRENCH_STAMPED, BagWriter, wrench_message
from vib_estimator.sim import arm_model
from vib_estimator.sim.signals import fig1_signal

EPOCH_NS = 1_700_000_000 * 1_000_000_000  # 2023-11-14 22:13:20 UTC, time of the first sample
TOPIC = '/coupling_torque'
TRUTH_TOPIC = '/vibration/ground_truth'
FRAME = 'arm_base'
COMPONENT = 'torque.z'
TRUTH_EVERY = 50  # samples between ground-truth messages (10 Hz at 500 Hz)

FIG1_TS = 0.001  # s, sample time of the Fig. 1 signal
FIG1_DURATION = 3.0  # s
FIG1_OMEGA = 10.0  # rad/s


def write_bag(path: Path, t: np.ndarray, signal: np.ndarray, f_true: np.ndarray) -> None:
    """One bag: the signal on :data:`TOPIC`, the ground truth on :data:`TRUTH_TOPIC`."""
    float64 = TYPESTORE.types['std_msgs/msg/Float64']
    stamps = EPOCH_NS + np.round(t * 1e9).astype(np.int64)
    with BagWriter(path) as bag:
        wrench = bag.add_topic(TOPIC, WRENCH_STAMPED)
        truth = bag.add_topic(TRUTH_TOPIC, 'std_msgs/msg/Float64')
        for k, (stamp, value, f) in enumerate(
            zip(stamps.tolist(), signal.tolist(), f_true.tolist())
        ):
            bag.write_message(wrench, stamp, wrench_message(stamp, FRAME, COMPONENT, value))
            if k % TRUTH_EVERY == 0:
                bag.write_message(truth, stamp, float64(data=f))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--out', type=Path, default=Path(__file__).resolve().parents[1] / 'bags')
    parser.add_argument('--seed', type=int, default=0)
    args = parser.parse_args(argv)

    t = np.arange(int(round(FIG1_DURATION / FIG1_TS))) * FIG1_TS
    recordings = {
        'arm_5_3': arm_model.experiment_5_3(args.seed),
        'arm_5_5': arm_model.experiment_5_5(args.seed),
        'fig1': arm_model.Recording(
            t,
            fig1_signal(t, args.seed, omega=FIG1_OMEGA),
            np.full(len(t), FIG1_OMEGA / (2 * math.pi)),
        ),
    }
    args.out.mkdir(parents=True, exist_ok=True)
    for name, rec in recordings.items():
        path = args.out / name
        shutil.rmtree(path, ignore_errors=True)
        write_bag(path, rec.t, rec.torque, rec.f_true)
        size = sum(f.stat().st_size for f in path.iterdir())
        print(f'{path}: {len(rec.t)} samples, {rec.t[-1] - rec.t[0]:.3f} s, {size / 1e6:.2f} MB')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
