#!/usr/bin/env python3
# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Draw what ``estimator_node`` publishes on ``vibration/mode_shapes`` for a record, headless.

    python scripts/render_mode_markers.py GEOMETRY.yaml ESTIMATES.jsonl OUT.png [--t 0.0]

ESTIMATES.jsonl: ``vib-estimator analyze ... --columns ...`` output (rows with ``mode``,
``frequency_hz``, ``damping`` and ``shape_<channel>``). Each mode's median shape goes through the
node's marker builder (:class:`vib_estimator.nodes.mode_markers.ModeShapeMarkers`, the
markers the node converts to ``visualization_msgs/Marker``) at animation time ``--t`` (0: the
largest deflection), and the markers are drawn with matplotlib as RViz would show them: the
undeformed wireframe grey, the deformed one coloured by amplitude (blue still, red the largest),
the sensors as dots, the labels as text. RViz itself is not available here; this is its stand-in
for docs/report.md.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from vib_estimator.analysis.plotting import pyplot
from vib_estimator.io.geometry import load_geometry
from vib_estimator.nodes.mode_markers import DEFAULTS, ModeShapeMarkers


def median_shapes(rows, channels):
    """Per mode: (median frequency, median damping, median signed shape)."""
    out = {}
    for k in sorted({r['mode'] for r in rows}):
        mine = [r for r in rows if r['mode'] == k]
        shape = np.median([[r[f'shape_{c}'] for c in channels] for r in mine], axis=0)
        zeta = np.median([r['damping'] if r['damping'] is not None else np.nan for r in mine])
        out[k] = (float(np.median([r['frequency_hz'] for r in mine])), float(zeta), shape)
    return out


def project(points: np.ndarray) -> np.ndarray:
    """An oblique view (x to the right, z up, y receding up-right), as a camera in RViz might."""
    points = np.asarray(points).reshape(-1, 3)
    return np.column_stack(
        (points[:, 0] + OBLIQUE * points[:, 1], points[:, 2] + OBLIQUE * points[:, 1])
    )


#: how far a metre along y shifts a point right and up in the drawing
OBLIQUE = 0.4


def draw(specs, path: str, title: str) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(13, 4.4))
    for s in specs:
        if s.kind == 'line_list':
            for i in range(0, len(s.points), 2):
                seg = project(s.points[i : i + 2])
                colour = s.colour if s.colours is None else s.colours[i : i + 2].mean(axis=0)
                ax.plot(*seg.T, color=colour, lw=1.0 if s.ns == 'undeformed' else 2.5,
                        ls='--' if s.ns == 'undeformed' else '-')  # fmt: skip
        elif s.kind == 'sphere_list':
            ax.scatter(*project(s.points).T, c=s.colours, s=18, zorder=3)
        elif s.kind == 'text':
            ax.text(*project(s.position)[0], s.text, ha='center', va='bottom', fontsize=9)
    ax.set_aspect('equal')
    ax.margins(0.03, 0.22)
    ax.set_xlabel('x (m), oblique view: y recedes up and to the right')
    ax.set_ylabel('z (m)')
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('geometry')
    parser.add_argument('estimates')
    parser.add_argument('out')
    parser.add_argument('--t', type=float, default=0.0, help='animation time, s')
    args = parser.parse_args()
    geometry = load_geometry(args.geometry)
    with open(args.estimates) as f:
        rows = [json.loads(line) for line in f if line.strip()]
    channels = [k[len('shape_') :] for k in rows[0] if k.startswith('shape_')]
    channels = [c for c in channels if not c.startswith(('phase_deg_', 'std_'))]
    markers = ModeShapeMarkers(
        geometry, channels, DEFAULTS['mode_shapes_scale'], DEFAULTS['mode_shapes_period_s']
    )
    for k, (f, zeta, shape) in median_shapes(rows, channels).items():
        markers.update(k, f, zeta, shape)
    draw(
        markers.markers(args.t),
        args.out,
        f"vibration/mode_shapes of {geometry.name}: the node's markers drawn headless "
        '(matplotlib; RViz is not available here)',
    )


if __name__ == '__main__':
    main()
