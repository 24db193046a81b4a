# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``vib-estimator``: the package's command line (offline analysis, paper figures, comparison,
demo).

Each sub-command lives in its own module exposing ``add_arguments(parser)`` and
``run(args) -> int``; this module only dispatches, importing the chosen one lazily so ``--help``
stays fast. Input a command refuses (:mod:`vib_estimator.errors`) ends as one ``error:`` line and
the exit code :func:`vib_estimator.errors.exit_code` gives it (2), here if the command does not
report it itself.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from typing import Optional, Sequence

from .errors import VibEstimatorError, report

COMMANDS = {
    'analyze': (
        'vib_estimator.analysis.analyze',
        'estimate frequencies in a recorded signal (CSV, MCAP, rosbag2)',
    ),
    'survey': (
        'vib_estimator.analysis.survey',
        'many recordings: one summary row each, trend plot, '
        'frequency-drift alarm; local or Dask-distributed',
    ),
    'reproduce': ('vib_estimator.analysis.reproduce', "reproduce the paper's Figs. 1 and 2"),
    'compare': (
        'vib_estimator.analysis.compare',
        'algebraic vs adaptive/FFT estimators (Table 2, Figs. 6-7, Cramer-Rao bound)',
    ),
    'demo': ('vib_estimator.demo', 'live demo: simulator + estimator node, three tip masses'),
    'warmup': (
        'vib_estimator.analysis.warm',
        'compile the estimator kernels now (make setup runs it; '
        'a first start then takes a second, not half a minute)',
    ),
    'reindex': (
        'vib_estimator.io.reindex',
        'rebuild the metadata.yaml of a rosbag2 directory from its '
        'storage files (repairs a cut last MCAP file)',
    ),
}


class Parser(argparse.ArgumentParser):
    """argparse with a bad argument reported as one ``error:`` line (no usage block), exit 2."""

    def error(self, message: str):
        self.exit(2, f'{self.prog}: error: {message} (see {self.prog} --help)\n')


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = Parser(prog='vib-estimator', description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest='command', required=True, metavar='COMMAND')
    chosen = (argv if argv is not None else sys.argv[1:])[:1]
    modules = {}
    for name, (module, help_text) in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        if chosen == [name]:
            modules[name] = importlib.import_module(module)
            modules[name].add_arguments(p)
    args = parser.parse_args(argv)
    #: the command line as given (a report quotes it)
    args.argv = ['vib-estimator', *(argv if argv is not None else sys.argv[1:])]
    try:
        return modules[args.command].run(args)
    except VibEstimatorError as err:
        return report(err, f'vib-estimator {args.command}')
    except BrokenPipeError:
        # the reader of stdout went away (e.g. `| head`): stop quietly, as Unix tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == '__main__':
    sys.exit(main())
