# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Mode identity over time (core/identity.py): the register every estimator shares, and the shape
measures it reads (core/shapes.py). The expectations are the documented figures (3 %, MAC 0.5, 3
and 8 analyses, 8 modes), not the constants."""

import math

import numpy as np
import pytest

from vib_estimator.core.identity import ModeRegister, continues
from vib_estimator.core.shapes import mac, normalise_shape


def test_mac_and_normalisation():
    a = np.array([1.0, -2.0, 0.5])
    assert mac(a, (0.3 - 2j) * a) == pytest.approx(1.0)
    assert mac(a, np.array([2.0, 1.0, 0.0])) == pytest.approx(0.0)
    s = normalise_shape((0.3 - 2j) * a)
    assert np.linalg.norm(s) == pytest.approx(1.0)
    assert np.allclose(s, a / -np.linalg.norm(a))  # the largest entry (-2) real and positive


def test_a_mode_continues_a_track_only_with_a_similar_shape():
    """``MAC_MATCH`` (0.5): a mode within MATCH_TOL of a known one continues it when their
    shapes' MAC is 0.7 (the scatter of a weakly excited mode's shape), not when it is 0.3
    (another mode at nearly the same frequency: a building's two bending directions)."""
    last = np.array([1.0, 0.0, 0.0])
    similar = np.array([1.0, math.sqrt(3 / 7), 0.0])  # MAC 0.7
    other = np.array([1.0, 0.0, math.sqrt(7 / 3)])  # MAC 0.3
    assert mac(similar, last) == pytest.approx(0.7) and mac(other, last) == pytest.approx(0.3)
    assert continues(5.05, similar, 5.0, last) == pytest.approx(0.01)
    assert continues(5.05, other, 5.0, last) is None
    assert continues(5.05, last, 5.0, last) == pytest.approx(0.01)
    assert continues(5.05, None, 5.0, last) == pytest.approx(0.01)  # no shape: frequency alone


def test_a_mode_continues_within_3_percent_and_not_beyond():
    """``MATCH_TOL`` (3 %): an estimate 1 % or 2.5 % from a known mode continues it (the scatter
    of one mode's estimates); one 10 % away (a second mode of a beam, a close pair) is another."""
    assert continues(5.05, None, 5.0, None) == pytest.approx(0.01)
    assert continues(5.125, None, 5.0, None) == pytest.approx(0.025)
    assert continues(5.5, None, 5.0, None) is None
    assert continues(4.5, None, 5.0, None) is None
    register = ModeRegister()
    numbers = [register.number(register.observe_one(f, t)) for t, f in enumerate((5.0, 5.5, 5.05))]
    assert numbers == [1, 2, 1] and len(register.modes) == 2


def test_match_prefers_published_modes_then_the_nearest():
    """A window's modes each take one known mode: published first, then the nearest."""
    register = ModeRegister(confirm=3, confirm_beside=3)
    near = register.observe(5.0, 0.0)
    register.settle({near}, 0.0)  # unpublished, seen once
    published = register.observe(5.1, 0.0)
    published.published = True
    # 5.04 is nearer 5.0 (0.8 %) than 5.1 (1.2 %), but 5.1 is published: it takes it
    assert register.match([5.02, 5.04]) == {1: published, 0: near}
    assert register.match([5.02])[0] is published
    assert register.match([5.02, 5.04, 5.03]).keys() == {0, 1}  # a mode continues one at most


def test_a_new_mode_publishes_after_3_observations_running_and_8_beside_a_published_one():
    """``CONFIRM`` (3) and ``CONFIRM_BESIDE`` (8), as the identifier builds its register: the
    first mode publishes at its third analysis running; a second, beside it, at its eighth; one
    missed analysis starts the count again; a published mode unseen for the forgetting time is
    lost, an unpublished one unseen at once."""
    from vib_estimator.core import ambient, identity

    register = ModeRegister(10.0, identity.CONFIRM, identity.CONFIRM_BESIDE, new=ambient._Track)

    def analysis(t, frequencies):
        match = register.match(frequencies)
        seen = {register.observe(f, t, None, match.get(i)) for i, f in enumerate(frequencies)}
        ready, found, lost = register.settle(seen, t)
        return sorted(m.frequency for m in ready), found, lost

    assert [analysis(t, [5.0]) for t in range(3)] == [([], 0, 0)] * 2 + [([5.0], 1, 0)]
    second = [analysis(t, [5.0, 9.0])[0] for t in range(3, 11)]
    assert second == [[5.0]] * 7 + [[5.0, 9.0]]
    assert register.number(register.modes[1]) == 2
    # a candidate missed once starts again
    out = [analysis(t, [5.0, 9.0, 12.0] if t != 15 else [5.0, 9.0]) for t in range(11, 25)]
    assert [12.0 in ready for ready, _, _ in out] == [False] * 12 + [True] * 2
    # 12 Hz missed for more than the forgetting time (10 s): lost; a candidate missed: forgotten
    out = [analysis(t, [5.0, 9.0] + ([7.0] if t == 25 else [])) for t in range(25, 37)]
    assert sum(lost for _, _, lost in out) == 1 and out[10][2] == 1  # at 35 s, 11 s unseen
    assert sorted(m.frequency for m in register.modes) == [5.0, 9.0]


def test_a_new_mode_as_strong_as_the_published_ones_needs_only_3_observations():
    """Beside a published mode, a new one at least as strong as the strongest published publishes
    after ``CONFIRM`` (3) observations running, a weaker one after ``CONFIRM_BESIDE`` (8): a
    coloured excitation's statistical poles beside a strong mode are weak; a mode stronger than
    the first one published (the 5 Hz mode of a 5 + 17 Hz record found after the 17 Hz one) is a
    mode. Without amplitudes (0: the estimators that publish at once) a new mode is beside."""
    from vib_estimator.core import ambient, identity

    def run(amplitudes, times=12):
        register = ModeRegister(
            10.0, identity.CONFIRM, identity.CONFIRM_BESIDE, new=ambient._Track
        )
        first = []
        for t in range(times):
            frequencies = [17.0] + ([5.0] if t >= 3 else [])
            match = register.match(frequencies)
            seen = {}
            for i, f in enumerate(frequencies):
                mode = register.observe(f, t, None, match.get(i))
                mode.amplitude = amplitudes[i]
                seen[mode] = i
            ready, _, _ = register.settle(seen, t)
            first += [(m.frequency, t) for m in ready if m.estimates == 0]
            for m in ready:
                m.estimates += 1
        return dict(first)

    # 17 Hz publishes at its third analysis (t = 2); 5 Hz, seen from t = 3
    assert run([0.55, 1.0]) == {17.0: 2, 5.0: 5}  # stronger: its third
    assert run([0.55, 0.55]) == {17.0: 2, 5.0: 5}  # as strong
    assert run([0.55, 0.5]) == {17.0: 2, 5.0: 10}  # weaker: its eighth
    assert run([0.0, 0.0]) == {17.0: 2, 5.0: 10}  # no amplitudes


@pytest.mark.parametrize('replace', [False, True])
def test_at_most_8_modes_are_known(replace):
    """``MAX_TRACKS`` (8): a register never holds more than 8 modes (a stream of ever new
    frequencies costs bounded memory and time); a full one takes no new mode (the identifier: its
    established modes are not pushed out by a window's statistical poles) or forgets its least
    recent one (``replace``: the joint free-decay estimator, auto)."""
    register = ModeRegister(replace=replace)
    frequencies = [1.2**k for k in range(12)]
    kept = [register.observe_one(f, float(t)) is not None for t, f in enumerate(frequencies)]
    assert len(register.modes) == 8
    held = sorted(m.frequency for m in register.modes)
    assert held == pytest.approx(frequencies[4:] if replace else frequencies[:8])
    assert kept == [True] * 12 if replace else [True] * 8 + [False] * 4
