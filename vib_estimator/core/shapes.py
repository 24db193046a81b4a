# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""A mode shape as the real numbers the outputs carry (``analyze``'s fields, the node's
``vibration/mode<k>/shape``): one definition for both.

A shape (:mod:`.multichannel`) is complex, one entry per channel, normalised to unit length with
its largest entry real and positive. Each channel is published as its **signed amplitude**
``|phi_c| * sign(Re phi_c)`` (a real, classically damped mode: the shape itself) and its **phase**
in degrees (0 or +-180 for a real mode).
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
