# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``vib-estimator demo``: the simulated arm and the estimator node live, through three tip masses.

Starts ``sim_node`` (Section 5.5's masses 30 -> 45.55 -> 61.17 g, sped up, publishing ``/clock``)
and ``estimator_node`` (``use_sim_time``, the paper's configuration) as subprocesses of the same
environment on a private ROS domain, and listens in this process to ``coupling_torque``,
``vibration/ground_truth``, ``vibration/frequency`` and ``vibration/reset``. Each estimate is
printed as it arrives next to the true (Eq. 23) frequency; at the end a Fig. 5/7-like PNG is
written and a table per mass printed. Exit status 0 only if every mass's median error is within
3 %.
``--shaping`` adds ``shaper_node`` and moves the arm, unshaped then shaped for the estimate.
``--operation`` drives the arm continuously, never at rest, and runs the estimator with
``excitation`` ambient (or auto) (:mod:`.operation`).

By role: :mod:`.session` (the domain, this process's node, the node subprocesses),
:mod:`.estimation` (the estimation demo and its table), :mod:`.shaping` (the shaping demo, its
measurement and table), :mod:`.plots` (both figures); this module holds the command's arguments
and :func:`run`.
"""

from __future__ import annotations

import argparse
import signal
import sys
import time

from ..control.shaping import SHAPERS
from ..sim.arm_model import MASSES_5_5, natural_frequency_hz
from .estimation import REAL_ARM_SIM_PARAMS, mass_g, run_estimation, summarise
from .operation import ESTIMATOR_EXCITATIONS, SIM_EXCITATIONS, run_operation
from .operation import truth as operation_truth
from .plots import plot_estimation, plot_shaping
from .session import PAPER_PARAMS, Listener, Record, Session, demo_domain, domain_id, sim_params
from .shaping import (
    MAX_STEP,
    MIN_SECONDS_PER_MOVE_PAIR,
    ShapedMove,
    ShapingDriver,
    measure_moves,
    run_shaping,
    shaping_events,
    summarise_shaping,
)

__all__ = [
    'add_arguments',
    'run',
    'Listener',
    'Record',
    'Session',
    'ShapedMove',
    'ShapingDriver',
    'PAPER_PARAMS',
    'REAL_ARM_SIM_PARAMS',
    'demo_domain',
    'domain_id',
    'mass_g',
    'measure_moves',
    'plot_estimation',
    'plot_shaping',
    'shaping_events',
    'sim_params',
    'summarise',
    'summarise_shaping',
]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The arguments of ``vib-estimator demo``."""
    parser.add_argument(
        '--speed',
        type=float,
        default=10.0,
        help='simulated seconds per wall-clock second (default 10)',
    )
    parser.add_argument(
        '--seconds-per-mass',
        type=float,
        default=8.0,
        help='simulated seconds spent on each tip mass (default 8)',
    )
    parser.add_argument(
        '--out',
        default=None,
        help='figure path (default out/demo.png, with --shaping out/shaping.png, with --real-arm '
        'out/demo_real_arm.png)',
    )
    parser.add_argument(
        '--domain-id',
        type=domain_id,
        default=None,
        help='ROS domain of the demo, 0-232 (default: ROS_DOMAIN_ID when set, '
        'else one of 1-101 from the process id)',
    )
    parser.add_argument(
        '--real-arm',
        action='store_true',
        help='the same schedule on a realistic rig (strain-gauge offset, coarse '
        "quantisation, a closed-loop limit cycle) with the estimator's "
        "defaults instead of the paper's configuration (docs/real_arm.md)",
    )
    parser.add_argument(
        '--shaping',
        action='store_true',
        help='input shaping: per mass a move unshaped, then the same move shaped '
        'by shaper_node for the estimate (figure out/shaping.png)',
    )
    parser.add_argument(
        '--shaper',
        default='zvd',
        choices=sorted(SHAPERS),
        help='with --shaping: the shaper of the shaped moves (default zvd)',
    )
    parser.add_argument(
        '--step',
        type=float,
        default=0.5,
        help='with --shaping: size of each move (a reference step), rad (default 0.5)',
    )
    _add_operation_arguments(parser)


def _add_operation_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        '--operation',
        action='store_true',
        help='in operation: the arm driven continuously (never at rest), the estimator with '
        'excitation ambient (docs/operation.md)',
    )
    parser.add_argument(
        '--excitation',
        default='ambient',
        choices=ESTIMATOR_EXCITATIONS,
        help="with --operation: estimator_node's excitation (default ambient)",
    )
    parser.add_argument(
        '--sim-excitation',
        default='ambient',
        choices=SIM_EXCITATIONS,
        help="with --operation: sim_node's excitation (default ambient)",
    )
    parser.add_argument(
        '--duration',
        type=float,
        default=80.0,
        help='with --operation: simulated seconds (default 80; > 30)',
    )


def _interrupt(signum, frame) -> None:
    raise KeyboardInterrupt


def run(args: argparse.Namespace) -> int:
    """Run the estimation demo (or with ``--shaping`` the shaping demo); the exit status."""
    from rclpy.executors import ExternalShutdownException

    if args.speed <= 0 or args.seconds_per_mass <= 2:
        print('error: --speed must be > 0 and --seconds-per-mass > 2', file=sys.stderr)
        return 2
    if args.shaping and (
        args.seconds_per_mass < MIN_SECONDS_PER_MOVE_PAIR or not 0 < args.step <= MAX_STEP
    ):
        print(
            f'error: with --shaping, --seconds-per-mass must be >= '
            f'{MIN_SECONDS_PER_MOVE_PAIR:g} and --step in (0, {MAX_STEP:g}] rad',
            file=sys.stderr,
        )
        return 2
    operation = getattr(args, 'operation', False)
    if operation and (args.shaping or not args.duration > 30):
        print(
            'error: --operation takes no --shaping, and --duration must be > 30', file=sys.stderr
        )
        return 2
    truth = [
        (i * args.seconds_per_mass, (i + 1) * args.seconds_per_mass, natural_frequency_hz(m))
        for i, m in enumerate(MASSES_5_5)
    ]
    if operation:
        truth = operation_truth(args.duration)
    wall_start = time.monotonic()
    session = Session(args, truth)
    # SIGTERM (a `kill`, a CI timeout) unwinds like Ctrl-C, so the nodes started are stopped too
    signal.signal(signal.SIGTERM, _interrupt)
    try:
        if args.shaping:
            return run_shaping(session, args, wall_start)
        if operation:
            return run_operation(session, args, wall_start)
        return run_estimation(session, args, wall_start)
    except RuntimeError as err:
        print(f'error: {err}', file=sys.stderr)
        return 1
    except (KeyboardInterrupt, ExternalShutdownException):
        print('interrupted', file=sys.stderr)
        return 130
    finally:
        session.close()
