# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Maximum-likelihood refinement of an estimate over its segment, and its standard deviation
(numba).

The algebraic estimate (Eqs. 7-12) is exact for a clean signal of its model but, with noise, its
spread grows with the window instead of falling (the moments weight the samples by powers of t,
not by their information). This module turns it into the maximum-likelihood estimate of the same
model over the samples the estimate used (the segment buffer the quality gate already holds), and
gives the standard deviation of the result from the Fisher information.

Models, on centred segment time u = tau - (tau_0 + tau_{n-1}) / 2 (centring decorrelates the
frequency from the phase and keeps the normal equations well conditioned)::

    sinusoid:          y = a sin(w u) + b cos(w u)                       theta = (a, b, w)
    biased-sinusoid:   y = a sin(w u) + b cos(w u) + c                   theta = (a, b, w, c)
    damped-sinusoid:   y = exp(-sigma u) (a sin(w_d u) + b cos(w_d u))   theta = (a, b, w_d, sigma)

(the damped model's natural frequency is w_n = sqrt(w_d^2 + sigma^2), its damping ratio
zeta = sigma / w_n: the quantities of the algebraic damped estimator.)

:func:`refine`: the linear parameters are first solved for at the algebraic (w, sigma) (variable
projection), then Gauss-Newton steps on all of theta (continued over growing prefixes of a long
segment, see :func:`refine`): ``J^T J delta = J^T r`` (J the Jacobian of
the model over the samples, r the residual). A step is kept only if it lowers the residual sum of
squares, so the result is never worse (in the likelihood) than the algebraic estimate it starts
from; they stop once the step of the frequency (and of sigma or c) is below ``STEP_TOL`` of its
std (from a start near the bound, after one or two steps); with 0 iterations the algebraic
estimate is returned untouched and only its std is computed.

Standard deviation: ``cov(theta) = s^2 (J^T J)^-1`` at the returned theta, with the residual
variance ``s^2 = RSS / (n - p)`` (p parameters): the exact Cramer-Rao bound of the model over those
samples with the noise variance estimated from the segment itself. For the damped model the std of
f_n and zeta follow by the delta method from the (w_d, sigma) block.

Coloured noise (:func:`coloured_std`): the optional band-pass prefilter turns white input noise w
(variance N0) into e = F w, whose covariance over the segment is N0 R (R_ij = rho(i - j), the
autocorrelation of the prefilter's impulse response). The least-squares fit is then still
unbiased, but ``cov(theta) = N0 G^-1 (J^T R J) G^-1`` (G = J^T J: the sandwich), and the residual
estimates N0 through ``E[RSS] = N0 (n rho(0) - tr(G^-1 J^T R J))``. The caller supplies
``J^T R J`` and rho(0) (the kernel filters the Jacobian's columns through the prefilter,
:func:`jacobian_row`). Over windows long against the filter's correlation time this tends to the
white-noise bound with the in-band noise density. Over a window short against it the residual has
a fraction of one degree of freedom (``n rho(0) - tr(...)`` ~ 0.16 over half a period of a
[f/2, 2f] band), so N0, and the std with it, can only be estimated roughly from the window: with
the true N0 the sandwich is calibrated there too (RMS error/std 0.98), with the estimated one ~1.7.

Cost: sines and cosines over the segment are advanced by a rotation (exact on uniform sampling,
resynced every 256 samples and whenever the step changes), the sums of a pass stay in registers,
variable projection sums only the linear columns, and the scratch arrays are the caller's (in the
kernel's state, allocated once): a default estimate over half a period costs one projection and
about two Gauss-Newton passes over its samples.
"""

from __future__ import annotations

import math

from .jit import jit

#: values of the kernel's model parameter
MODEL_SINUSOID, MODEL_BIASED, MODEL_DAMPED = 0, 1, 2
#: refine() result layout: frequency (Hz), damping ratio, their standard deviations, the fitted
#: model's R^2 (about the segment's mean) and amplitude (at the segment's centre), and its RSS
R_F, R_DAMP, R_FSTD, R_DSTD, R_FIT, R_AMP, R_RSS, N_RESULT = range(8)  # N_RESULT: slots
TWO_PI = 2.0 * math.pi
_RESYNC = 256
#: Gauss-Newton stops once the step of the nonlinear parameters is below this fraction of their std
STEP_TOL = 1e-3
#: floats of scratch :func:`refine` needs (allocated once by the caller, see :func:`_workspace`)
N_WORK = 96


@jit
def _workspace(work):
    """Named views of the caller's scratch (``N_WORK`` floats): theta, the best theta, J^T r,
    J^T J, its inverse, the best theta's inverse, Gauss-Jordan's augmented matrix and its
    scaling."""
    return (
        work[0:4],
        work[4:8],
        work[8:12],
        work[12:28].reshape((4, 4)),
        work[28:44].reshape((4, 4)),
        work[44:60].reshape((4, 4)),
        work[60:92].reshape((4, 8)),
        work[92:96],
    )


@jit(inline='always')
def _copy(dst, src):
    """dst[:n] = src[:n] element by element (numba's array assignment brings its broadcasting and
    the formatting of its error message into the compile)."""
    for i in range(src.shape[0]):
        dst[i] = src[i]


@jit
def _accumulate(model, seg, n, tc, th, jtj, jtr, linear=False):
    """One pass over the segment at theta: J^T J, J^T r into ``jtj``, ``jtr``; returns the RSS.

    Columns of J: d/da = E sin, d/db = E cos, d/dw = u E (a cos - b sin), and d/dc = 1 (biased) or
    d/dsigma = -u E (a sin + b cos) (damped), with E = exp(-sigma u) (1 for the other models).
    ``linear``: only the columns of the linear parameters (a, b, c; variable projection). The sums
    are scalars (registers) until the end of the pass, and the sines advance by rotation within
    blocks of ``_RESYNC`` samples.
    """
    a, b, w = th[0], th[1], th[2]
    sig = th[3] if model == MODEL_DAMPED else 0.0
    off = th[3] if model == MODEL_BIASED else 0.0
    col3 = model == MODEL_BIASED or (model == MODEL_DAMPED and not linear)
    a00 = a01 = a02 = a03 = a11 = a12 = a13 = a22 = a23 = a33 = 0.0
    r0 = r1 = r2 = r3 = rss = 0.0
    rc = rs = re = 0.0
    d_prev = -1.0
    for block in range(0, n, _RESYNC):
        u = seg[0, block] - tc
        sn, cs, e = math.sin(w * u), math.cos(w * u), math.exp(-sig * u)
        for i in range(block, min(block + _RESYNC, n)):
            if i > block:
                u = seg[0, i] - tc
                d = seg[0, i] - seg[0, i - 1]
                if abs(d - d_prev) > 1e-9 * d:
                    rc, rs, re, d_prev = math.cos(w * d), math.sin(w * d), math.exp(-sig * d), d
                sn, cs = sn * rc + cs * rs, cs * rc - sn * rs
                e *= re
            osc = e * (a * sn + b * cs)
            r = seg[1, i] - osc - off
            j0 = e * sn
            j1 = e * cs
            r0 += j0 * r
            r1 += j1 * r
            a00 += j0 * j0
            a01 += j0 * j1
            a11 += j1 * j1
            rss += r * r
            if not linear:
                j2 = u * e * (a * cs - b * sn)
                r2 += j2 * r
                a02 += j0 * j2
                a12 += j1 * j2
                a22 += j2 * j2
            if col3:
                j3 = 1.0 if model == MODEL_BIASED else -u * osc
                r3 += j3 * r
                a03 += j0 * j3
                a13 += j1 * j3
                a33 += j3 * j3
                if not linear:
                    a23 += j2 * j3
    _store_normal_equations(
        model, jtj, jtr, (a00, a01, a02, a03, a11, a12, a13, a22, a23, a33), (r0, r1, r2, r3)
    )
    return rss


@jit(inline='always')
def _store_normal_equations(model, jtj, jtr, upper, rhs):
    """J^T J (symmetric, from its upper triangle row by row) and J^T r; the sinusoid's 4th column
    (not a parameter of it) stays zero."""
    npar = 3 if model == MODEL_SINUSOID else 4
    jtj[:, :] = 0.0
    jtr[:] = 0.0
    k = 0
    for i in range(4):
        for j in range(i, 4):
            if j < npar:
                jtj[i, j] = upper[k]
                jtj[j, i] = upper[k]
            k += 1
        if i < npar:
            jtr[i] = rhs[i]


@jit
def _invert(a, idx, m, out, aug, scale):
    """Inverse of the symmetric block a[idx][:, idx] (m x m) into out[:m, :m]; False if singular.

    Gauss-Jordan with partial pivoting on the Jacobi-scaled matrix (the columns of J have different
    units, so scaling keeps the pivots meaningful); ``aug`` (m x 2m used) and ``scale`` (m) are
    scratch.
    """
    w = aug
    for i in range(m):
        dii = a[idx[i], idx[i]]
        if not dii > 0.0:
            return False
        scale[i] = 1.0 / math.sqrt(dii)
    for i in range(m):
        for j in range(m):
            w[i, j] = a[idx[i], idx[j]] * scale[i] * scale[j]
            w[i, m + j] = 0.0
        w[i, m + i] = 1.0
    for col in range(m):
        piv = col
        for r in range(col + 1, m):
            if abs(w[r, col]) > abs(w[piv, col]):
                piv = r
        if not abs(w[piv, col]) > 1e-14:
            return False
        for j in range(2 * m):
            w[col, j], w[piv, j] = w[piv, j], w[col, j]
        inv_p = 1.0 / w[col, col]
        for j in range(2 * m):
            w[col, j] *= inv_p
        for r in range(m):
            if r != col and w[r, col] != 0.0:
                fac = w[r, col]
                for j in range(2 * m):
                    w[r, j] -= fac * w[col, j]
    for i in range(m):
        for j in range(m):
            out[i, j] = w[i, m + j] * scale[i] * scale[j]
    return True


@jit(inline='always')
def _solve_linear(model, seg, n, tc, work):
    """Variable projection: the least-squares a, b (and c) at theta's w (and sigma)."""
    th, _, jtr, jtj, cov, _, aug, scale = _workspace(work)
    th[0] = th[1] = 0.0
    if model == MODEL_BIASED:
        th[3] = 0.0
    _accumulate(model, seg, n, tc, th, jtj, jtr, True)
    idx = (0, 1, 3, 3)  # a, b, c (the first m); four entries: _invert's one signature
    m = 3 if model == MODEL_BIASED else 2
    if not _invert(jtj, idx, m, cov, aug, scale):
        return False
    for i in range(m):
        acc = 0.0
        for j in range(m):
            acc += cov[i, j] * jtr[idx[j]]
        th[idx[i]] = acc
    return True


@jit(inline='always')
def _newton_step(npar, th, cov, jtr, s2):
    """theta += (J^T J)^-1 J^T r; True if the step of the nonlinear parameters (w, and sigma or c)
    is below ``STEP_TOL`` of their std (s^2 (J^T J)^-1 with the current residual variance ``s2``)
    or rounding: theta is then converged and the step is not worth a pass."""
    small = True
    for i in range(npar):
        delta = 0.0
        for j in range(npar):
            delta += cov[i, j] * jtr[j]
        if i >= 2 and abs(delta) > max(STEP_TOL * math.sqrt(s2 * cov[i, i]), 1e-13 * abs(th[i])):
            small = False
        th[i] += delta
    return small


@jit
def _gauss_newton(model, seg, n, iterations, work):
    """Fit theta (``work``) over seg[:, :n]: variable projection at theta's (w, sigma), then
    Gauss-Newton.

    A step is kept only if it lowers the RSS; the iterations stop early once a step is negligible
    (:func:`_newton_step`). Returns the best RSS (inf if no fit) and leaves the best theta in
    theta and its (J^T J)^-1 in the best inverse of the workspace.
    """
    th, best, jtr, jtj, cov, best_cov, aug, scale = _workspace(work)
    npar = 3 if model == MODEL_SINUSOID else 4
    tc = 0.5 * (seg[0, 0] + seg[0, n - 1])
    if not _solve_linear(model, seg, n, tc, work):
        return math.inf
    _copy(best, th)
    best_rss = math.inf
    for k in range(iterations + 1):
        rss = _accumulate(model, seg, n, tc, th, jtj, jtr, False)
        if not (rss < best_rss and _invert(jtj, (0, 1, 2, 3), npar, cov, aug, scale)):
            break
        best_rss = rss
        _copy(best, th)
        for i in range(4):
            _copy(best_cov[i], cov[i])
        if k == iterations or _newton_step(npar, th, cov, jtr, rss / (n - npar)):
            break
        if not (th[2] > 0.0 and math.isfinite(th[2])):
            break
    _copy(th, best)
    return best_rss


@jit(inline='always')
def _first_prefix(seg, n, npar, w0):
    """Length of the continuation's first window: n halved while it spans at least half a period
    (and 2 npar + 2 samples), so the prefixes double up to n exactly."""
    shortest = 2 * npar + 2
    while shortest < n and seg[0, shortest - 1] - seg[0, 0] < math.pi / w0:
        shortest += 1
    m = n
    while m >= 2 * shortest:
        m //= 2
    return m


@jit
def refine(model, seg, n, w0, sigma0, iterations, res, work):
    """Refine the algebraic estimate over the segment ``seg[:, :n]`` (rows: tau, y); fill ``res``.

    ``w0`` (rad/s) and ``sigma0`` (1/s, damped model) start the fit; ``iterations`` Gauss-Newton
    steps at most, each kept only if it lowers the RSS. Over more than a period the fit is
    continued: first over a prefix of the segment between half a period and a period long (where
    the algebraic estimate is near the bound, well inside the likelihood's main lobe), then over
    prefixes doubling in length up to the whole segment, each started from the last, so the start
    always lies in the main lobe of the next window's likelihood. ``res``: frequency (Hz; the
    natural frequency for the damped model), damping ratio (NaN unless damped), their std (white
    noise), the RSS, and (iterations > 0) the fitted model's R^2 and amplitude (:func:`_goodness`).
    ``work``: ``N_WORK`` floats of scratch; on return it holds the fitted theta and its
    (J^T J)^-1 (:func:`coloured_std` uses them). Returns False (res untouched) when no fit is
    possible.
    """
    npar = 3 if model == MODEL_SINUSOID else 4
    if n <= npar + 1 or not w0 > 0.0:
        return False
    th, _, _, _, _, cov, _, _ = _workspace(work)
    th[:] = 0.0
    th[2] = w0
    if model == MODEL_DAMPED:
        th[3] = sigma0
    m = _first_prefix(seg, n, npar, w0) if iterations > 0 else n
    while True:
        rss = _gauss_newton(model, seg, m, iterations, work)
        if m >= n or rss == math.inf:
            break
        m = n if 4 * m > n else 2 * m
    if rss == math.inf:
        return False
    _moments_of_result(model, th, cov, rss / (n - npar), res)
    res[R_RSS] = rss
    if iterations > 0:
        _goodness(seg, n, th, rss, res)
    return True


@jit(inline='always')
def _goodness(seg, n, th, rss, res):
    """R^2 = 1 - RSS / (sum of squares about the mean) of the fitted model, and its amplitude.

    The quality gate judges the refined model by these (the damped model's own residual, so a
    decaying sine over many periods passes). R^2 = -1 when the segment has no variance.
    """
    ymean = 0.0
    for i in range(n):
        ymean += seg[1, i]
    ymean /= n
    sstot = 0.0
    for i in range(n):
        d = seg[1, i] - ymean
        sstot += d * d  # what numba makes of ** 2 (Python's pow may round differently)
    res[R_FIT] = 1.0 - rss / sstot if sstot > 0.0 else -1.0
    res[R_AMP] = math.hypot(th[0], th[1])


@jit
def _moments_of_result(model, th, cov, s2, res):
    """Frequency, damping ratio and their std from theta and s^2 (J^T J)^-1 (delta method)."""
    w = th[2]
    if model == MODEL_DAMPED:
        sig = th[3]
        wn = math.sqrt(w * w + sig * sig)
        # gradients of w_n and zeta = sigma / w_n with respect to (w_d, sigma)
        gw = (w / wn, sig / wn)
        wn3 = wn * (wn * wn)  # what numba makes of wn**3 (Python's pow may round differently)
        gz = (-sig * w / wn3, w * w / wn3)
        var_w = s2 * (
            gw[0] * gw[0] * cov[2, 2] + 2 * gw[0] * gw[1] * cov[2, 3] + gw[1] * gw[1] * cov[3, 3]
        )
        var_z = s2 * (
            gz[0] * gz[0] * cov[2, 2] + 2 * gz[0] * gz[1] * cov[2, 3] + gz[1] * gz[1] * cov[3, 3]
        )
        res[R_F] = wn / TWO_PI
        res[R_DAMP] = sig / wn
        res[R_DSTD] = math.sqrt(var_z) if var_z >= 0.0 else math.nan
    else:
        var_w = s2 * cov[2, 2]
        res[R_F] = w / TWO_PI
        res[R_DAMP] = math.nan
        res[R_DSTD] = math.nan
    res[R_FSTD] = math.sqrt(var_w) / TWO_PI if var_w >= 0.0 else math.nan


@jit
def jacobian_row(model, th, u, row):
    """The Jacobian's row at centred time u (the columns of :func:`_accumulate`) into row[:4]."""
    a, b, w = th[0], th[1], th[2]
    sig = th[3] if model == MODEL_DAMPED else 0.0
    e = math.exp(-sig * u)
    sn, cs = math.sin(w * u), math.cos(w * u)
    row[0] = e * sn
    row[1] = e * cs
    row[2] = u * e * (a * cs - b * sn)
    row[3] = 1.0 if model == MODEL_BIASED else -u * e * (a * sn + b * cs)


@jit
def coloured_std(model, n, gram, rho0, res, work):
    """Replace the std in ``res`` by the sandwich under coloured noise (module docstring).

    ``gram`` = J^T R J at the fitted theta, ``rho0`` = rho(0), ``work`` as :func:`refine` left
    it (theta and G^-1), ``res[R_RSS]`` the fit's RSS. A degenerate case (no residual degree of
    freedom left) gives NaN stds: the white-noise ones would be wrong, not merely rough.
    """
    th, _, _, _, out, gi, _, _ = _workspace(work)
    npar = 3 if model == MODEL_SINUSOID else 4
    trace = 0.0
    for i in range(npar):
        for j in range(npar):
            trace += gi[i, j] * gram[j, i]
    dof = n * rho0 - trace
    if not dof > 0.0:
        res[R_FSTD] = res[R_DSTD] = math.nan
        return
    for i in range(npar):
        for j in range(npar):
            acc = 0.0
            for k in range(npar):
                for m in range(npar):
                    acc += gi[i, k] * gram[k, m] * gi[m, j]
            out[i, j] = acc
    _moments_of_result(model, th, out, res[R_RSS] / dof, res)
