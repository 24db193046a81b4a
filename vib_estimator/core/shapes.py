# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""A mode shape: its normalisation, the MAC of two, and the real numbers the outputs carry
(``analyze``'s fields, the node's ``vibration/mode<k>/shape``): one definition for all.

A shape (:mod:`.ssi`, :mod:`.multichannel_free`) is complex, one entry per channel, normalised
to unit length with its largest entry real and positive (:func:`normalise_shape`). Each channel
is published as its **signed amplitude** ``|phi_c| * sign(Re phi_c)`` (a real, classically damped
mode: the shape itself) and its **phase** in degrees (0 or +-180 for a real mode).
"""

from __future__ import annotations

import numpy as np

#: the rows of a published shape, in order: signed amplitudes, phases (degrees), uncertainties
#: (the names of ``analyze``'s fields, less the channel)
SHAPE_ROWS = ('shape', 'shape_phase_deg', 'shape_std')


def signed_amplitudes(shape) -> np.ndarray:
    """``|phi_c| * sign(Re phi_c)`` of each entry of ``shape``."""
    shape = np.asarray(shape)
    return np.abs(shape) * np.copysign(1.0, shape.real)


def phases_deg(shape) -> np.ndarray:
    """The phase of each entry of ``shape``, degrees."""
    return np.degrees(np.angle(np.asarray(shape)))


def mac(a: np.ndarray, b: np.ndarray) -> float:
    """Modal assurance criterion ``|a^H b|^2 / (|a|^2 |b|^2)`` of two (complex) shapes: 1 for
    shapes equal up to a complex scale, 0 for orthogonal ones."""
    a, b = np.asarray(a), np.asarray(b)
    den = float(np.vdot(a, a).real * np.vdot(b, b).real)
    return float(abs(np.vdot(a, b)) ** 2 / den) if den > 0 else 0.0


def normalise_shape(phi: np.ndarray) -> np.ndarray:
    """``phi`` scaled to unit length with its largest entry real and positive."""
    k = int(np.argmax(np.abs(phi)))
    scale = phi[k] / abs(phi[k]) * np.linalg.norm(phi) if abs(phi[k]) > 0 else 1.0
    return phi / scale
