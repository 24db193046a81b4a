# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``python -m vib_estimator.control [--damping Z] [--plot FILE.png]``: what an error of the
frequency estimate costs each shaper -- the residual vibration (% of an unshaped move's) when the
true frequency is off the design by 1, 2, 5, 10 and 20 %, the shaper's delay in periods, and the
sensitivity curves as a figure."""

from __future__ import annotations

import argparse
import sys
from typing import List, Optional, Sequence

import numpy as np

from .shaping import SHAPERS, design, sensitivity

ERRORS_PCT = (1.0, 2.0, 5.0, 10.0, 20.0)


def table(damping: float) -> List[str]:
    """Rows: shaper, delay in periods, residual % at each error (worst of -e and +e)."""
    rows = [
        f'{"shaper":>7} {"delay (periods)":>15} '
        + ' '.join(f'{"±%g %%" % e:>8}' for e in ERRORS_PCT)
    ]
    for name in SHAPERS:
        s = design(name, 1.0, damping)
        worst = [100 * np.max(sensitivity(s, [1 - e / 100, 1 + e / 100])) for e in ERRORS_PCT]
        rows.append(f'{name:>7} {s.duration:15.2f} ' + ' '.join(f'{v:8.3g}' for v in worst))
    return rows


#: the sensitivity plot's vertical span, % (above 100: the unshaped "none" line clears the frame)
PLOT_TOP_PCT = 110.0


def plot(path: str, damping: float):
    """The sensitivity curves of every shaper (``none``, the unshaped 100 %, dashed black);
    returns the Figure."""
    from ..analysis.plotting import pyplot

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    r = np.linspace(0.5, 1.5, 1001)
    for name in SHAPERS:
        style = dict(color='k', ls='--', lw=1.0) if name == 'none' else {}
        ax.plot(r, 100 * sensitivity(design(name, 1.0, damping), r), label=name, **style)
    ax.set(
        xlabel='true frequency / design frequency',
        ylabel='residual vibration (%)',
        ylim=(0, PLOT_TOP_PCT),
        title=f'Sensitivity curves (zeta = {damping:g})',
    )
    ax.grid(alpha=0.3)
    ax.legend(loc='center', fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return fig


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog='python -m vib_estimator.control', description=__doc__.splitlines()[0]
    )
    parser.add_argument(
        '--damping',
        type=float,
        default=0.0,
        help='damping ratio of the mode and of the design (default 0)',
    )
    parser.add_argument('--plot', help='write the sensitivity curves to this PNG')
    args = parser.parse_args(argv)
    try:
        print('\n'.join(table(args.damping)))
        if args.plot:
            plot(args.plot, args.damping)
    except ValueError as err:
        print(f'error: {err}', file=sys.stderr)
        return 2
    return 0


if __name__ == '__main__':
    sys.exit(main())
