# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""core.spectra: Welch's spectrum and the prominent peaks, in numpy, against scipy.signal's."""

import numpy as np
import pytest
from scipy.signal import find_peaks
from scipy.signal import welch as scipy_welch

from vib_estimator.core.spectra import peaks_by_prominence, welch


@pytest.mark.parametrize('seed', range(6))
def test_welch_is_scipy_s_to_the_fft_s_rounding(seed):
    rng = np.random.default_rng(seed)
    n, channels = int(rng.integers(300, 20000)), 1 + seed % 3
    t = np.arange(n) / 500.0
    y = rng.standard_normal((n, channels)) + np.sin(2 * np.pi * rng.uniform(1, 50) * t)[:, None]
    nper = int(min(n, rng.integers(64, 12000)))  # odd and even
    want_f, want = scipy_welch(y, 500.0, nperseg=nper, axis=0, detrend='constant')
    got_f, got = welch(y, 500.0, nper)
    assert np.array_equal(got_f, want_f) and got.shape == want.shape
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-13 * np.max(want))


@pytest.mark.parametrize('seed', range(6))
@pytest.mark.parametrize('minimum', [0.0, 0.5, 3.0, 10.0])
def test_the_peaks_are_scipy_s(seed, minimum):
    rng = np.random.default_rng(seed)
    _, psd = scipy_welch(rng.standard_normal(5000) + np.sin(np.arange(5000) * 0.3), 500.0)
    level = 10 * np.log10(psd)
    plateaus = np.round(rng.standard_normal(400), 1)  # ties: a plateau's middle
    for x in (level, plateaus, plateaus[:3], np.ones(5)):
        assert list(peaks_by_prominence(x, minimum)) == list(find_peaks(x, prominence=minimum)[0])


def test_choice_no_longer_imports_scipy_signal():
    import subprocess
    import sys

    code = (
        'import sys, numpy as np; from vib_estimator.core import choice; '
        't = np.arange(20000) / 500; choice.spectral_peaks(t, np.sin(31.4 * t)); '
        'sys.exit("scipy.signal" in sys.modules)'
    )
    assert subprocess.run([sys.executable, '-c', code]).returncode == 0
