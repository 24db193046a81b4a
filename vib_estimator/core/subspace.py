# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Subspace analysis of one short window: the damped sinusoids it holds (compiled, numba).

A window ``x[0..m-1]`` of uniformly spaced samples is modelled as a sum of damped complex
exponentials ``x[n] = sum_i c_i z_i^n`` (each real damped sinusoid a conjugate pair, an offset or
a slow trend a real pole). Everything is written out in loops over contiguous rows, without
temporaries, their sums reassociated (``FAST``) so that they vectorise (no BLAS or LAPACK call: at
these sizes a call costs more than the arithmetic):

* **Covariance** (:func:`hankel_cov`): ``R = H^T H`` of the ``(m - L) x (L + 1)`` Hankel matrix of
  the window (``L = m // 3``), built from its first row and the shift recursion
  ``R[i+1, j+1] = R[i, j] + x[i+m-L] x[j+m-L] - x[i] x[j]``.
* **Signal subspace** (:func:`orthogonal_iteration`): one step of orthogonal iteration
  ``Q <- orth(R Q)`` on ``P`` columns, warm-started from the previous window of the same scale
  (the eigenvalues of the signal are decades above the noise's, so one step per window tracks
  them); the column norms are the eigenvalue estimates ``lam``. The last column is noise (``P``
  exceeds twice the modes sought), the order is the number of columns ``ratio`` times above it
  (and above ``1e-12`` of the largest: a noise-free window).
* **Poles** (:func:`esprit_poly`, :func:`poly_roots`): the signal subspace is spanned by the
  vectors ``z_i^n``, so shifting it by one sample is a rotation ``Phi`` whose eigenvalues are the
  poles (ESPRIT, least squares ``Q[:-1] Phi = Q[1:]``); they are found as the roots of its
  characteristic polynomial (Faddeev-LeVerrier) by the Aberth-Ehrlich iteration, started from the
  scale's previous poles (a sliding window keeps its signal's poles: a few steps suffice).
* **Amplitudes and fit** (:func:`fit_poles`): the real basis ``Re z^n, Im z^n`` per pair (one
  column per real pole), ``n`` counted back from the window's last sample, fitted to the window by
  least squares; each pair gives its frequency (cycles per sample), damping ratio, amplitude at the
  last sample and energy in the window, the window its residual variance and R^2, and its
  level: the positive real poles' sum at the last sample (the offset and any slow trend).
* **Undamped refinement** (:func:`refine_undamped`, on request): over 1-3 cycles two modes closer
  than 1.5 in frequency trade their frequencies against their dampings (with the dampings unknown
  the Cramer-Rao bound of 10 / 13 Hz, 1 : 0.5, SNR 30 dB is 1.1 / 1.6 % at 1.4 periods, 0.23 /
  0.36 % at 2; with them known 0.25 / 0.38 % at 1.4), so such pairs are moved onto the unit circle
  and their frequencies refined by Gauss-Newton on the least-squares residual, the amplitudes
  eliminated (variable projection).

:func:`analyse` chains them and writes one row per pair (``R_NU``, ``R_ZETA``, ``R_AMP``,
``R_ENERGY``).
"""

from __future__ import annotations

import math

import numpy as np

from .jit import jit

R_NU, R_ZETA, R_AMP, R_ENERGY, N_R = range(5)  # N_R: the slots' number
DECAY_MAX = 12.0  # poles decaying (or growing) more than e^12 over the window are dropped
REAL_TOL = 1e-7  # |Im z| below this: a real pole
ROOT_ITER = 40
ROOT_TOL = 1e-10  # Aberth steps below this: converged
REFINE_ZETA = 0.1  # pairs damped less than this, with another within REFINE_RATIO in
REFINE_RATIO = 1.5  # frequency (a close pair), are refined as undamped ...
REFINE_CYCLES = (1.0, 3.0)  # ... when they hold this many cycles in the window,
REFINE_ITER = 4  # ... by at most this many Gauss-Newton steps,
REFINE_STEP = 1e-7  # forward differences of this many radians per sample
#: reassociated sums (vectorised loops); no assumption about NaN or infinities
FAST = {'reassoc', 'contract', 'nsz', 'arcp'}


@jit(fastmath=FAST)
def hankel_cov(x, lag, r):
    """R = H^T H of the window's Hankel matrix (module docstring) into r[:lag+1, :lag+1]."""
    m = len(x)
    rows = m - lag
    for j in range(lag + 1):
        s = 0.0
        for k in range(rows):
            s += x[k] * x[k + j]
        r[0, j] = s
        r[j, 0] = s
    for i in range(lag):
        for j in range(i, lag):
            v = r[i, j] + x[i + rows] * x[j + rows] - x[i] * x[j]
            r[i + 1, j + 1] = v
            r[j + 1, i + 1] = v


@jit
def descending(lam):
    """The order of lam's values, descending, NaN last, ties in place (an insertion sort: what
    np.argsort(-lam) gives for the fewer than 15 columns here, numba's quicksort being an
    insertion sort below 15 elements; this one costs less to compile than numpy's sort
    machinery). The mode tracker's median interval is read from it too."""
    n = lam.shape[0]
    order = np.empty(n, dtype=np.int64)
    for i in range(n):
        v = -lam[i]
        j = i
        while j > 0 and (
            v < -lam[order[j - 1]] or (math.isnan(-lam[order[j - 1]]) and not math.isnan(v))
        ):
            order[j] = order[j - 1]
            j -= 1
        order[j] = i
    return order


@jit(fastmath=FAST)
def orthogonal_iteration(r, n, q, lam):
    """One step Q <- orth(R Q) on q[:n, :P] (modified Gram-Schmidt), columns sorted by their
    eigenvalue estimates lam (descending); returns the new columns as the rows of a contiguous
    (P, n) array (the loops run over contiguous rows)."""
    npc = q.shape[1]
    qt = np.empty((npc, n))
    for k in range(npc):
        for i in range(n):
            qt[k, i] = q[i, k]
    w = np.zeros((npc, n))
    for k in range(npc):
        for j in range(n):
            a = qt[k, j]
            for i in range(n):
                w[k, i] += r[j, i] * a  # R is symmetric: row j of R is its column j
    for k in range(npc):
        for j in range(k):
            d = 0.0
            for i in range(n):
                d += w[j, i] * w[k, i]
            for i in range(n):
                w[k, i] -= d * w[j, i]
        norm = 0.0
        for i in range(n):
            norm += w[k, i] * w[k, i]
        norm = math.sqrt(norm)
        lam[k] = norm
        if norm > 0.0:
            for i in range(n):
                w[k, i] /= norm
        else:
            w[k, :] = 0.0
            w[k, k % n] = 1.0
    order = descending(lam)
    ranked = np.empty(npc)
    for k in range(npc):
        ranked[k] = lam[order[k]]
    for k in range(npc):
        lam[k] = ranked[k]
    for k in range(npc):
        for i in range(n):
            qt[k, i] = w[order[k], i]
            q[i, k] = qt[k, i]
    return qt


@jit
def cholesky_solve(a, b):
    """Solve a x = b (b: a matrix of right-hand columns) for a symmetric positive (semi)definite
    a (a tiny ridge keeps it regular)."""
    n = a.shape[0]
    c = np.zeros((n, n))
    ridge = 1e-13 * max(np.trace(a) / max(n, 1), 1e-300)
    for j in range(n):
        s = a[j, j] + ridge
        for k in range(j):
            s -= c[j, k] * c[j, k]
        c[j, j] = math.sqrt(max(s, ridge))
        for i in range(j + 1, n):
            s = a[i, j]
            for k in range(j):
                s -= c[i, k] * c[j, k]
            c[i, j] = s / c[j, j]
    x = b.copy()
    for col in range(x.shape[1]):
        for i in range(n):
            v = x[i, col]
            for k in range(i):
                v -= c[i, k] * x[k, col]
            x[i, col] = v / c[i, i]
        for i in range(n - 1, -1, -1):
            v = x[i, col]
            for k in range(i + 1, n):
                v -= c[k, i] * x[k, col]
            x[i, col] = v / c[i, i]
    return x


@jit(fastmath=FAST)
def esprit_poly(qt, n, p):
    """Characteristic polynomial (monic, low coefficients first) of the rotation Phi of the signal
    subspace (the first p rows of qt, each a column of Q), Q[:-1] Phi = Q[1:] in least squares
    (Faddeev-LeVerrier recursion)."""
    g = np.zeros((p, p))
    rhs = np.zeros((p, p))
    for i in range(p):
        for j in range(p):
            sg = 0.0
            sr = 0.0
            for r in range(n - 1):
                sg += qt[i, r] * qt[j, r]
                sr += qt[i, r] * qt[j, r + 1]
            g[i, j] = sg
            rhs[i, j] = sr
    phi = cholesky_solve(g, rhs)
    c = np.zeros(p + 1)
    c[p] = 1.0
    mk = np.zeros((p, p))
    nxt = np.empty((p, p))
    for k in range(1, p + 1):
        for i in range(p):
            for j in range(p):
                v = 0.0
                for col in range(p):
                    v += phi[i, col] * mk[col, j]
                nxt[i, j] = v
        mk, nxt = nxt, mk
        for i in range(p):
            mk[i, i] += c[p - k + 1]
        tr = 0.0
        for i in range(p):
            for j in range(p):
                tr += phi[i, j] * mk[j, i]
        c[p - k] = -tr / k
    return c[:p]


@jit
def poly_roots(a, start):
    """Roots of z^p + a[p-1] z^(p-1) + ... + a[0] (Aberth-Ehrlich iteration), started from
    start[:, k] = (re, im) where finite and distinct from the others (the previous window's
    poles: a sliding window keeps them), else from a circle; the roots are written back to
    start."""
    p = len(a)
    z = np.empty(p, dtype=np.complex128)
    for k in range(p):
        z[k] = 0.9 * np.exp(1j * (2.0 * math.pi * (k + 0.25) / p + 0.1))
        if k < start.shape[1] and math.isfinite(start[0, k]) and math.isfinite(start[1, k]):
            w = start[0, k] + 1j * start[1, k]
            if all_apart(z, k, w):
                z[k] = w
    for _ in range(ROOT_ITER):
        moved = 0.0
        for k in range(p):
            f = 1.0 + 0.0j
            df = 0.0 + 0.0j
            for j in range(p - 1, -1, -1):
                df = df * z[k] + f
                f = f * z[k] + a[j]
            if f == 0.0:
                continue
            ratio = f / df
            s = 0.0 + 0.0j
            for j in range(p):
                if j != k:
                    s += 1.0 / (z[k] - z[j])
            step = ratio / (1.0 - ratio * s)
            z[k] -= step
            moved = max(moved, abs(step))
        if moved < ROOT_TOL:
            break
    start[:] = math.nan
    for k in range(min(p, start.shape[1])):
        start[0, k] = z[k].real
        start[1, k] = z[k].imag
    return z


@jit
def all_apart(z, k, w):
    """Whether w lies apart (1e-9) from z[:k]."""
    for j in range(k):
        if abs(z[j] - w) < 1e-9:
            return False
    return True


@jit(fastmath=FAST)
def _basis(m, poles):
    """The real least-squares basis of the poles (module docstring), one row per column, and
    each pole's columns (0: dropped, 1: real, 2: a pair; a pole with negative imaginary part is
    its pair's twin)."""
    kind = np.zeros(len(poles), dtype=np.int64)
    ncol = 0
    for i in range(len(poles)):
        z = poles[i]
        if z.imag >= -REAL_TOL and abs(z) > 0.0 and abs(math.log(abs(z))) * m <= DECAY_MAX:
            kind[i] = 2 if z.imag > REAL_TOL else 1
            ncol += kind[i]
    basis = np.empty((ncol, m))
    col = 0
    for i in range(len(poles)):
        if kind[i] == 0:
            continue
        z = poles[i]
        w = np.exp(np.log(z) * (1 - m))
        for n in range(m):
            basis[col, n] = w.real
            if kind[i] == 2:
                basis[col + 1, n] = w.imag
            w *= z
        col += kind[i]
    return basis, kind


@jit(fastmath=FAST)
def _normal_solve(basis, x):
    """Least-squares coefficients c of the basis rows (ncol x m) to x: (B B^T) c = B x."""
    m = len(x)
    ncol = basis.shape[0]
    gram = np.empty((ncol, ncol))
    bx = np.empty((ncol, 1))
    for i in range(ncol):
        for j in range(i + 1):
            v = 0.0
            for n in range(m):
                v += basis[i, n] * basis[j, n]
            gram[i, j] = v
            gram[j, i] = v
        v = 0.0
        for n in range(m):
            v += basis[i, n] * x[n]
        bx[i, 0] = v
    return cholesky_solve(gram, bx)[:, 0]


@jit(fastmath=FAST)
def _lsq(x, basis):
    """Least-squares coefficients of the basis rows to x and the residual x - basis^T c."""
    c = _normal_solve(basis, x)
    res = x.copy()
    for n in range(len(x)):
        for i in range(basis.shape[0]):
            res[n] -= basis[i, n] * c[i]
    return c, res


@jit(fastmath=FAST)
def fit_poles(x, poles, rows):
    """Least-squares amplitudes of the poles (module docstring); returns (pairs written to rows,
    residual variance, R^2, level: the positive real poles' sum at the last sample, the window's
    offset and slow trend)."""
    m = len(x)
    basis, kind = _basis(m, poles)
    ncol = basis.shape[0]
    if ncol == 0 or ncol >= m:
        return 0, math.nan, math.nan, math.nan
    c, res = _lsq(x, basis)
    mean = np.mean(x)
    total = 0.0
    rss = 0.0
    for n in range(m):
        rss += res[n] * res[n]
        total += (x[n] - mean) ** 2
    npair = 0
    col = 0
    level = 0.0
    for i in range(len(poles)):
        if kind[i] == 1 and poles[i].real > 0.0:
            level += c[col]
        if kind[i] == 2:
            lz = np.log(poles[i])
            energy = 0.0
            for n in range(m):
                v = basis[col, n] * c[col] + basis[col + 1, n] * c[col + 1]
                energy += v * v
            rows[npair, R_NU] = lz.imag / (2.0 * math.pi)
            rows[npair, R_ZETA] = -lz.real / abs(lz)
            rows[npair, R_AMP] = math.hypot(c[col], c[col + 1])
            rows[npair, R_ENERGY] = energy
            npair += 1
        col += kind[i]
    return npair, rss / (m - ncol), 1.0 - rss / total if total > 0.0 else math.nan, level


# ---- undamped refinement of a short window (the first estimates of a close pair) --------------
@jit
def _circle_residual(x, poles, idx, theta):
    """Residual of the least-squares fit of x with poles[idx[i]] replaced by e^(j theta[i])
    (undamped); empty when the basis is degenerate."""
    z = poles.copy()
    for i in range(len(idx)):
        z[idx[i]] = math.cos(theta[i]) + 1j * math.sin(theta[i])
    basis = _basis(len(x), z)[0]
    if basis.shape[0] == 0 or basis.shape[0] >= len(x):
        return np.empty(0)
    return _lsq(x, basis)[1]


@jit
def _close_pairs(poles, m):
    """Indices of the poles refined over m samples (:func:`refine_undamped`): upper pairs damped
    below ``REFINE_ZETA`` with ``REFINE_CYCLES`` in the window and another such within
    ``REFINE_RATIO`` in frequency."""
    light = np.empty(len(poles), dtype=np.int64)
    k = 0
    for i in range(len(poles)):
        z = poles[i]
        if z.imag > REAL_TOL and abs(z) > 0.0:
            lz = np.log(z)
            cycles = lz.imag * m / (2.0 * math.pi)
            if (
                abs(lz.real) < REFINE_ZETA * abs(lz)
                and REFINE_CYCLES[0] <= cycles <= REFINE_CYCLES[1]
            ):
                light[k] = i
                k += 1
    close = np.empty(k, dtype=np.int64)
    nc = 0
    for i in range(k):
        for j in range(k):
            a = np.angle(poles[light[i]]) / np.angle(poles[light[j]])
            if i != j and max(a, 1.0 / a) < REFINE_RATIO:
                close[nc] = light[i]
                nc += 1
                break
    return close[:nc]


@jit(inline='always')
def refine_undamped(x, poles):
    """The close pairs of poles (:func:`_close_pairs`) moved onto the unit circle, their angles
    refined by Gauss-Newton on the variable-projection residual of window x
    (amplitudes eliminated, Jacobian by forward differences), a step kept only if it
    lowers the residual sum of squares; returns the new poles, or poles themselves when the
    refined fit is not better than the undamped start (the fallback: ESPRIT's poles)."""
    idx = _close_pairs(poles, len(x))
    k = len(idx)
    if k == 0:
        return poles
    theta = np.empty(k)
    for i in range(k):
        theta[i] = np.angle(poles[idx[i]])
    res = _circle_residual(x, poles, idx, theta)
    if len(res) == 0:
        return poles
    rss = np.sum(res * res)
    rss0 = rss
    jac = np.empty((k, len(x)))
    for _ in range(REFINE_ITER):
        for i in range(k):
            up = theta.copy()
            up[i] += REFINE_STEP
            ru = _circle_residual(x, poles, idx, up)
            if len(ru) == 0:
                return poles
            jac[i, :] = (ru - res) / REFINE_STEP
        step = -_normal_solve(jac, res)  # minimises |res + jac^T step|
        trial = theta + step
        rt = _circle_residual(x, poles, idx, trial)
        if len(rt) == 0 or not np.sum(rt * rt) < rss:
            break
        theta = trial
        res = rt
        rss = np.sum(rt * rt)
        if np.max(np.abs(step)) < ROOT_TOL:
            break
    if not rss < rss0:
        return poles
    z = poles.copy()
    for i in range(k):
        z[idx[i]] = math.cos(theta[i]) + 1j * math.sin(theta[i])
    return z


@jit
def init_subspace(q):
    """A start for the orthogonal iteration: orthonormal cosines of spread frequencies."""
    n, npc = q.shape
    for k in range(npc):
        for i in range(n):
            q[i, k] = math.cos(math.pi * (k + 0.5) * (i + 0.5) / n)
        acc = 0.0  # element by element: no array expression to compile
        for i in range(n):
            acc += q[i, k] ** 2
        norm = math.sqrt(acc)
        for i in range(n):
            q[i, k] /= norm


@jit(inline='always')
def analyse(x, q, lam, roots, ratio, rows, undamped=False):
    """The damped sinusoids of window x (module docstring), updating its scale's subspace q,
    eigenvalues lam and poles roots (rows re and im, NaN: none), their lightly damped pairs
    refined as undamped (:func:`refine_undamped`) if ``undamped``: (pairs in rows, residual
    variance, R^2, level: :func:`fit_poles`); (0, nan, nan, nan) for none."""
    lag = len(x) // 3
    n = lag + 1
    r = np.empty((n, n))
    hankel_cov(x, lag, r)
    qt = orthogonal_iteration(r, n, q, lam)
    npc = q.shape[1]
    noise = lam[npc - 1]
    p = 0
    while p < npc and lam[p] > ratio * noise and lam[p] > 1e-12 * lam[0]:
        p += 1
    if p == 0:
        return 0, math.nan, math.nan, math.nan
    poles = poly_roots(esprit_poly(qt, n, p), roots)
    return fit_poles(x, refine_undamped(x, poles) if undamped else poles, rows)
