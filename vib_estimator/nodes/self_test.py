# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The estimator node's self-test, with no rclpy: known tones through a fresh estimator.

:func:`self_test` runs three seeded tones (a sine at 40 dB SNR each, one after the other, each
through its own fresh estimator of the given configuration, batch path; for ``excitation``
ambient or auto a white-noise-driven mode at each tone, over three identifier windows) and
reports the median error of each tone's estimates. The tones sit across the configured
``band_hz`` (geometrically at 1/4, 1/2 and 3/4 of it), or, without a band, across
:func:`default_band` of the sampling rate. The node answers its ``~/self_test`` service with
it, off the data path: the live estimator is not touched, in a Python process of its own
(:func:`in_process`; ``python -m vib_estimator.nodes.self_test CONFIG_JSON``), so that its
records and estimators never weigh on the node's memory. (ArduPilot's GyroFFT has the same kind
of check.)
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from dataclasses import dataclass
from typing import Any, Callable, List, Optional, Tuple

import numpy as np

from ..core.config import EstimatorConfig
from ..core.factory import create_estimator
from ..sim.ambient import ambient_record

#: sampling rate of the tones when the input's is not known yet, Hz
DEFAULT_RATE_HZ = 500.0
#: signal-to-noise ratio of the tones, dB
SNR_DB = 40.0
#: a tone passes when the median of its estimates is within this relative error
TOLERANCE = 0.01
#: each tone lasts this many of its periods (more when min_periods asks for longer segments),
#: and with ``band_hz`` this many periods of its lower edge (the prefilter's settling: a 11.25 Hz
#: tone of 10 periods through a 2-20 Hz band gave no estimate, and the self-test failed)
PERIODS = 10.0
#: at most this many samples per tone
MAX_SAMPLES = 200_000
SEED = 0
#: ``excitation`` ambient or auto: each tone is a white-noise-driven mode at this damping ratio
#: over this many identifier windows (the identifier publishes from its first full window on;
#: a pure sine, undamped, is no mode it confirms)
AMBIENT_ZETA = 0.01
AMBIENT_WINDOWS = 3.0
#: the longest a self-test's own process may take, s (the identifier's three tones: 2-4 s)
PROCESS_TIMEOUT_S = 600.0


@dataclass(frozen=True)
class ToneResult:
    """One tone of the self-test."""

    frequency_hz: float
    estimates: int
    median_hz: float  # NaN without estimates
    note: str = ''  # why no estimate could be expected (e.g. above Nyquist)

    @property
    def error(self) -> float:
        """Relative error of the median estimate (NaN without estimates)."""
        return self.median_hz / self.frequency_hz - 1

    @property
    def passed(self) -> bool:
        return self.estimates > 0 and abs(self.error) <= TOLERANCE

    def describe(self) -> str:
        if self.note:
            return f'{self.frequency_hz:.4g} Hz: {self.note}'
        if not self.estimates:
            return f'{self.frequency_hz:.4g} Hz: no estimate'
        return (
            f'{self.frequency_hz:.4g} Hz: median {self.median_hz:.6g} Hz of '
            f'{self.estimates} estimates, error {100 * self.error:+.4f} %'
        )


def default_band(sample_rate_hz: float) -> Tuple[float, float]:
    """The band the tones span without ``band_hz``: fs/250 to fs/25 (2 to 20 Hz at 500 Hz), where
    the default configuration resolves a tone in about half a period with >= 25 samples a
    period."""
    return sample_rate_hz / 250, sample_rate_hz / 25


def tone_frequencies(band_hz: Optional[Tuple[float, float]], sample_rate_hz: float) -> List[float]:
    """Three tones at 1/4, 1/2 and 3/4 of the band on a logarithmic scale."""
    lo, hi = band_hz if band_hz is not None else default_band(sample_rate_hz)
    return [lo * (hi / lo) ** q for q in (0.25, 0.5, 0.75)]


def run_tone(
    config: EstimatorConfig,
    frequency_hz: float,
    sample_rate_hz: float,
    seed: int = SEED,
    create: Optional[Callable[[EstimatorConfig], Any]] = None,
) -> ToneResult:
    """One tone through a fresh estimator of ``config`` (``create(config)``; default
    :func:`~vib_estimator.core.modes.create_estimator`)."""
    if frequency_hz >= sample_rate_hz / 2:
        return ToneResult(
            frequency_hz,
            0,
            math.nan,
            f'above the Nyquist frequency {sample_rate_hz / 2:.6g} Hz of the input',
        )
    amplitude = max(1.0, 10 * config.min_amplitude)
    if config.excitation in (
        'ambient',
        'auto',
    ):  # a driven mode, over windows the identifier needs
        seconds = min(AMBIENT_WINDOWS * config.ambient_window_s, MAX_SAMPLES / sample_rate_hz)
        mode = [(frequency_hz, AMBIENT_ZETA, amplitude**2 / 2)]
        t, y, _ = ambient_record(seconds, sample_rate_hz, mode, SNR_DB, seed)
    else:
        seconds = max(PERIODS, 4 * (config.min_periods + 1)) / frequency_hz
        if config.band_hz is not None:  # and the band's prefilter settles: periods of its edge
            seconds = max(seconds, PERIODS / config.band_hz[0])
        n = min(MAX_SAMPLES, int(math.ceil(seconds * sample_rate_hz)))
        rng = np.random.default_rng(seed)
        t = np.arange(n) / sample_rate_hz
        y = amplitude * np.sin(2 * np.pi * frequency_hz * t + rng.uniform(0, 2 * np.pi))
        y += rng.normal(0.0, amplitude / math.sqrt(2) * 10 ** (-SNR_DB / 20), n)
    estimates = (create or create_estimator)(config).process(t, y)
    median = float(np.median(estimates.frequency_hz)) if len(estimates) else math.nan
    return ToneResult(frequency_hz, len(estimates), median)


def self_test(
    config: EstimatorConfig,
    sample_rate_hz: Optional[float] = None,
    create: Optional[Callable[[EstimatorConfig], Any]] = None,
) -> Tuple[bool, str]:
    """(all tones passed, one line per tone) for ``config`` at the input's sampling rate
    (:data:`DEFAULT_RATE_HZ` when not known), through estimators ``create`` makes (see
    :func:`run_tone`)."""
    rate = sample_rate_hz if sample_rate_hz and math.isfinite(sample_rate_hz) else DEFAULT_RATE_HZ
    results = [
        run_tone(config, f, rate, SEED + i, create)
        for i, f in enumerate(tone_frequencies(config.band_hz, rate))
    ]
    ok = all(r.passed for r in results)
    head = (
        f'{"passed" if ok else "FAILED"}: 3 tones at {rate:.6g} Hz sampling, SNR '
        f'{SNR_DB:g} dB, tolerance {100 * TOLERANCE:g} % of the median'
    )
    if config.band_hz is not None and config.band_hz[1] >= rate / 2:
        head += (
            f' (band_hz upper edge {config.band_hz[1]:g} Hz is at or above the Nyquist frequency '
            f'{rate / 2:.6g} Hz)'
        )
    return ok, '\n'.join([head] + [r.describe() for r in results])


def in_process(
    config: EstimatorConfig, sample_rate_hz: Optional[float] = None
) -> Optional[Tuple[bool, str]]:
    """:func:`self_test` in a child Python process (this module run with ``-m``, the
    configuration and the rate as JSON; its own session, so a terminal's Ctrl-C meant for the
    node does not reach it): the tones' records, their estimators and what the C heap keeps of
    them stay out of the caller's memory (the node kept 12 MB after its first self-test under
    the identifier, docs/soak.md). None when the process could not run or answer (the caller
    then runs :func:`self_test` itself)."""
    fields = {name: getattr(config, name) for name in EstimatorConfig.names()}
    request = json.dumps({'config': fields, 'rate': sample_rate_hz})
    try:
        done = subprocess.run(
            [sys.executable, '-m', 'vib_estimator.nodes.self_test', request],
            capture_output=True,
            text=True,
            timeout=PROCESS_TIMEOUT_S,
            start_new_session=True,
        )
        answer = json.loads(done.stdout.strip().splitlines()[-1])
        return bool(answer['ok']), str(answer['text'])
    except (OSError, subprocess.SubprocessError, ValueError, KeyError, IndexError):
        return None


def main(argv: Optional[List[str]] = None) -> int:
    """``python -m vib_estimator.nodes.self_test CONFIG_JSON``: :func:`in_process`'s child;
    prints ``{"ok": ..., "text": ...}``."""
    request = json.loads((sys.argv[1:] if argv is None else argv)[0])
    fields = {k: tuple(v) if isinstance(v, list) else v for k, v in request['config'].items()}
    ok, text = self_test(EstimatorConfig(**fields), request['rate'])
    print(json.dumps({'ok': ok, 'text': text}))
    return 0


if __name__ == '__main__':
    sys.exit(main())
