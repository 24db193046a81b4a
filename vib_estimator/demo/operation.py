# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``vib-estimator demo --operation``: the arm tracked while it never rests (issue 20).

``sim_node`` drives the arm continuously (``excitation`` = ambient, a broadband disturbance torque
at the tip, or random, a band-limited random motor command; one tip mass,
:data:`OPERATION_MASS_KG`) and ``estimator_node`` runs with ``excitation`` ambient (or auto) and
``ambient_window_s`` = :data:`WINDOW_S`; each estimate is printed as it arrives against Eq. 23's
frequency, then a summary. PASS when at least :data:`MIN_WITHIN` of the estimates are within
:data:`WITHIN_PCT` % of Eq. 23 and there are at least :data:`MIN_ESTIMATES` of them.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Optional

import numpy as np

from ..sim.arm_model import Move, natural_frequency_hz
from .session import Session, sim_params

#: the tip mass the arm carries, kg (Section 5.5's middle one: 1.33 Hz)
OPERATION_MASS_KG = 0.04555
#: estimator_node's sliding window, s (docs/operation.md: ~15 correlation times of the arm's mode)
WINDOW_S = 20.0
#: PASS: this share of the estimates within WITHIN_PCT of Eq. 23, and at least MIN_ESTIMATES
MIN_WITHIN = 0.9
WITHIN_PCT = 2.0
MIN_ESTIMATES = 5
#: the driven simulator's excitations (sim_node ``excitation``) and the estimator's
SIM_EXCITATIONS = ('ambient', 'random')
ESTIMATOR_EXCITATIONS = ('ambient', 'auto')


def truth(duration: float) -> list[tuple[float, float, float]]:
    """The demo's one stretch: (0, duration, Eq. 23's frequency)."""
    return [(0.0, duration, natural_frequency_hz(OPERATION_MASS_KG))]


def summarise_operation(est_f, f0: float) -> tuple[list[str], bool]:
    """Summary lines and whether the run passes."""
    f = np.asarray(est_f, dtype=float)
    if not len(f):
        return ['no estimate'], False
    err = (f - f0) / f0 * 100
    within = float(np.mean(np.abs(err) <= WITHIN_PCT))
    rows = [
        f'{"f0 Hz":>6} {"n":>4} {"median err %":>12} {"median |err| %":>14} '
        f'{"within " + format(WITHIN_PCT, "g") + " %":>12} {"> 5 %":>5}',
        f'{f0:6.4f} {len(f):4d} {np.median(err):12.2f} {np.median(np.abs(err)):14.2f} '
        f'{100 * within:11.1f}% {int(np.sum(np.abs(err) > 5)):5d}',
    ]
    return rows, within >= MIN_WITHIN and len(f) >= MIN_ESTIMATES


def arm_geometry() -> Optional[str]:
    """config/geometry/arm.yaml of the source tree or of the installed package
    (share/vib_estimator); None if neither has it (the demo then publishes no mode_shapes)."""
    candidates = [Path(__file__).resolve().parents[2] / 'config' / 'geometry' / 'arm.yaml']
    try:
        from ament_index_python import packages

        share = packages.get_package_share_directory('vib_estimator')
        candidates.append(Path(share) / 'config' / 'geometry' / 'arm.yaml')
    except (ImportError, LookupError, OSError, ValueError):
        pass
    return next((str(p) for p in candidates if p.is_file()), None)


def run_operation(session: Session, args: argparse.Namespace, wall_start: float) -> int:
    """The operation demo: the driven arm, every estimate against Eq. 23."""
    from ..nodes.sim_node import schedule_to_array

    duration = args.duration
    f0 = truth(duration)[0][2]
    print(
        f'demo --operation: ROS domain {session.domain}, {duration:g} s simulated at '
        f'{args.speed:g}x, the arm ({OPERATION_MASS_KG * 1e3:g} g, Eq. 23: {f0:.4f} Hz) driven '
        f'by sim_node excitation {args.sim_excitation}, estimator_node excitation '
        f'{args.excitation} (window {WINDOW_S:g} s: the first estimates after it)',
        flush=True,
    )
    geometry = arm_geometry()
    session.start_estimator(
        [f'excitation:={args.excitation}', f'ambient_window_s:={WINDOW_S}']
        + ([f'geometry_file:={geometry}'] if geometry else [])
    )
    if geometry:
        print(
            "demo --operation: vibration/mode_shapes draws the arm's mode in RViz: rviz2 -d "
            f'{Path(geometry).parents[1] / "mode_shapes.rviz"} (frame world)',
            flush=True,
        )
    schedule = schedule_to_array([Move(0.0, 0.0, 1.0, OPERATION_MASS_KG)])
    sim = session.start_sim(
        sim_params(args.speed, duration, schedule, 2) + [f'excitation:={args.sim_excitation}']
    )
    session.finish_sim(sim, duration, args.speed)
    rec = session.listener.record
    rows, ok = summarise_operation(rec.est_f, f0)
    print('\n' + '\n'.join(rows))
    print(
        f'\n{len(rec.t)} samples, {len(rec.est_t)} estimates in '
        f'{time.monotonic() - wall_start:.1f} s'
    )
    print(
        f'PASS: {100 * MIN_WITHIN:g} % or more of the estimates within {WITHIN_PCT:g} %'
        if ok
        else f'FAIL: fewer than {MIN_ESTIMATES} estimates or fewer than '
        f'{100 * MIN_WITHIN:g} % within {WITHIN_PCT:g} %'
    )
    return 0 if ok else 1
