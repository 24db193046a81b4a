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


def numpy_peaks(x, minimum):
    """The peaks by prominence with numpy's minima over each peak's whole range (scipy's
    find_peaks refuses NaN)."""
    n, found, i = len(x), [], 1
    while i < n - 1:
        if x[i - 1] < x[i]:
            ahead = i + 1
            while ahead < n - 1 and x[ahead] == x[i]:
                ahead += 1
            if x[ahead] < x[i]:
                found.append((i + ahead - 1) // 2)
                i = ahead
        i += 1
    keep = []
    for p in found:
        higher = np.flatnonzero(x[:p] > x[p])
        left = float(np.min(x[(higher[-1] + 1 if len(higher) else 0) : p + 1]))
        higher = np.flatnonzero(x[p + 1 :] > x[p])
        right = float(np.min(x[p : (p + 1 + higher[0] if len(higher) else n)]))
        if x[p] - max(left, right) >= minimum:
            keep.append(p)
    return keep


@pytest.mark.parametrize('scan', [0, 1, 3, 10**6])
def test_the_peaks_are_scipy_s_whichever_way_the_higher_sample_is_found(monkeypatch, scan):
    """The prominence's search in Python floats, then with numpy beyond ``SCAN`` samples: the same
    peaks with either alone (NaN and infinities between included)."""
    from vib_estimator.core import spectra

    monkeypatch.setattr(spectra, 'SCAN', scan)
    rng = np.random.default_rng(scan % 7)
    for n in (1, 2, 3, 50, 400, 3000):
        for x in (np.cumsum(rng.standard_normal(n)), np.round(rng.standard_normal(n), 1)):
            for minimum in (0.0, 1.0):
                want = list(find_peaks(x, prominence=minimum)[0])
                assert list(peaks_by_prominence(x, minimum)) == want
        x = rng.standard_normal(n)
        x[rng.integers(0, n, 2)] = (np.nan, np.inf)
        assert list(peaks_by_prominence(x, 0.5)) == numpy_peaks(x, 0.5)


def test_a_spectrum_s_peaks_search_in_python_floats_and_numpy_beyond_the_scan(monkeypatch):
    """A decision's spectrum (5001 bins of noise and a tone, ~1300 local maxima): most searches
    for a higher sample end within ``SCAN`` samples, in Python floats (at 0, every one goes to
    numpy); a tall peak's goes on with numpy (not in Python floats to the spectrum's ends)."""
    from vib_estimator.core import spectra

    y = np.random.default_rng(0).standard_normal(30000) + np.sin(np.arange(30000) * 0.3)
    _, psd = scipy_welch(y, 500.0, nperseg=10000)
    calls = []

    class Counted:
        def __getattr__(self, name):
            return getattr(np, name)

        @staticmethod
        def flatnonzero(a):
            calls.append(len(a))
            return np.flatnonzero(a)

    monkeypatch.setattr(spectra, 'np', Counted())
    peaks = peaks_by_prominence(10 * np.log10(psd), 0.0)
    assert len(peaks) > 1000
    assert 0 < len(calls) < len(peaks) / 4
