# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Several channels, one set of modes: the joint identifier (``analyze --columns``,
``core.ambient`` of several channels) vs pyOMA2's multi-channel SSI-cov vs each channel alone.

    .venv/bin/python benchmarks/bench_channels.py [--seeds 3] [--no-peer]
        [--real-data ../shared/real-data] [--ref REV] [--cost-only] [--free-only]

1. The 5-storey shear frame (``vib_estimator.sim.frame``: modes 0.89-6.00 Hz, zeta 2 %, one
   channel per storey, 20 dB, 50 Hz, 600 s; window 60 s): per mode the median and RMS relative
   frequency error, the damping median over the truth and the median MAC against the exact shape;
   the peer: pyOMA2 SSI-cov on the consecutive non-overlapping 60 s windows of the same records
   (all channels, block rows 20, orders to 30, the pole nearest the true frequency at order 20:
   ``mpe(order_in=20)`` -- told the frequencies, a generous peer); each channel alone
   (``excitation ambient``, the single-channel identifier): the best channel's RMS error per mode;
   and on the same windows: the joint estimate whose window is a peer window, beside the peer's.
2. A mode invisible on two of three channels (2.5 Hz on channel c only): found or not, and how far.
3. The real Heritage Court Tower record (6 channels, 40 Hz, 327.7 s, window 120 s, band 0.5-6 Hz):
   published modes found (>= 10 estimates within 2 %), share of estimates > 2 % from every one.
4. Cost: 8 channels at 500 Hz (4 modes 3-40 Hz, 120 s, window 30 s) as multiples of real time
   (record seconds per CPU second, each identifier warmed up first) beside one channel of the
   same record through the single-channel identifier, same run (with ``--ref REV``: beside
   revision REV's, ``reference_cost``); and 6 channels at 1 kHz fed as a node would, 1 s
   blocks (``process``) and sample by sample (``update``): multiples of real time and the
   slowest block / sample (an analysis), CPU time.
5. Free decays (``excitation free``, ``core.multichannel_free``; ``--free-only``: this alone): a
   5 Hz, zeta 1 % pluck of shape (1, -0.6, 0.2) on three channels, 6 s at 500 Hz, white noise
   0.02 on each, 10 seeds: the joint estimates' RMS relative frequency error and RMS error/std
   beside each channel alone through the single-channel estimator, for the default, the damped
   model and ``modes: 1``; and 5 Hz on channels a, b only with 17 Hz on c only (``modes: 2``):
   each mode's estimates, median error and median MAC against its true shape.
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np
from bench_operation import HCT_FILE, HCT_MODES, REAL_DATA, ssi_cov_window  # benchmarks/

from vib_estimator.core import EstimatorConfig, ambient, create_estimator
from vib_estimator.core.ambient import HOP_S, AmbientEstimator
from vib_estimator.core.shapes import mac
from vib_estimator.core.ssi import block_rows
from vib_estimator.extras import optional
from vib_estimator.sim.frame import frame_record, modal_record

warnings.filterwarnings('ignore', category=RuntimeWarning)
FRAME_FS = 50.0
FRAME_S = 600.0
WINDOW_S = 60.0
ZETA = 0.02
#: the peer's block rows (those of the joint identifier with two channels, ``ssi.block_rows``)
PEER_ROWS = block_rows(2)
#: an estimate counts for a mode within this relative distance
NEAR = 0.05


def per_mode(freq, truth):
    """Per true mode: the relative errors of the estimates nearest to it within :data:`NEAR`."""
    truth = np.asarray(truth)
    if not len(freq):
        return [np.empty(0)] * len(truth)
    rel = freq[:, None] / truth[None, :] - 1
    near = np.argmin(np.abs(rel), axis=1)
    return [rel[(near == j) & (np.abs(rel[:, j]) <= NEAR), j] for j in range(len(truth))]


def rms(x):
    return float(np.sqrt(np.mean(np.square(x)))) if len(x) else float('nan')


def peer(y, fs, freqs):
    """pyOMA2 multi-channel SSI-cov on consecutive :data:`WINDOW_S` windows: per mode the
    relative errors, damping ratios and the windows' last sample indices."""
    errs = [[] for _ in freqs]
    zetas = [[] for _ in freqs]
    ends = [[] for _ in freqs]
    n = int(WINDOW_S * fs)
    for start in range(0, len(y) - n + 1, n):
        res = ssi_cov_window(y[start : start + n], fs, freqs, PEER_ROWS)
        for j, (f, fn, xi) in enumerate(zip(freqs, *(res or ((), ())))):
            if np.isfinite(fn) and abs(fn / f - 1) <= NEAR:
                errs[j].append(fn / f - 1)
                zetas[j].append(xi)
                ends[j].append(start + n - 1)
    return [np.array(e) for e in errs], [np.array(z) for z in zetas], ends


def joint_every_second(config, names, t, y):
    """The joint identifier's output with an analysis every :data:`ambient.HOP_S` whatever the
    window."""
    share, ambient.HOP_SHARE = ambient.HOP_SHARE, 0.0
    try:
        return AmbientEstimator(config, names).process(t, y)
    finally:
        ambient.HOP_SHARE = share


def same_windows(t, estimates, j, f, ends, hop):
    """Pairs (joint error, index into the peer's list) of the joint estimates of mode ``j``
    whose window is a peer window (its end within half a ``hop`` of the window's last sample)."""
    e = estimates
    out = []
    for i, end in enumerate(ends):
        close = np.flatnonzero(
            (np.abs(e.t - t[end]) <= hop / 2) & (np.abs(e.frequency_hz / f - 1) <= NEAR)
        )
        if len(close):
            k = close[np.argmin(np.abs(e.frequency_hz[close] / f - 1))]
            out.append((e.frequency_hz[k] / f - 1, i))
    return out


def frame(seeds, with_peer):
    config = EstimatorConfig(excitation='ambient', ambient_window_s=WINDOW_S)
    print(
        f'## 5-storey shear frame: {FRAME_FS:g} Hz, {FRAME_S:g} s, zeta {ZETA:g}, 20 dB, '
        f'{seeds} seeds, window {WINDOW_S:g} s'
    )
    joint = {k: [] for k in ('err', 'zeta', 'mac')}
    peer_err, peer_zeta, single = None, None, None
    paired = [[] for _ in range(5)]  # per mode: (joint error, peer error) on the same windows
    for seed in range(1, seeds + 1):
        t, y, freqs, shapes = frame_record(FRAME_S, FRAME_FS, ZETA, 20.0, seed)
        names = [f's{i}' for i in range(1, 6)]
        # every second (HOP_S), not every hop_s of the window: the peer's windows, which end on
        # whole seconds, are then among the identifier's (same_windows)
        r = joint_every_second(config, names, t, y)
        e = r.estimates
        errs = per_mode(e.frequency_hz, freqs)
        rel = e.frequency_hz[:, None] / freqs[None, :] - 1
        near = np.argmin(np.abs(rel), axis=1)
        if seed == 1:
            joint = {k: [[] for _ in freqs] for k in ('err', 'zeta', 'mac')}
            peer_err = [[] for _ in freqs]
            peer_zeta = [[] for _ in freqs]
            single = [[[] for _ in freqs] for _ in names]
        for j in range(len(freqs)):
            m = (near == j) & (np.abs(rel[:, j]) <= NEAR)
            joint['err'][j].extend(errs[j])
            joint['zeta'][j].extend(e.damping[m])
            joint['mac'][j].extend(mac(s, shapes[:, j]) for s in r.shapes[m])
        for c in range(len(names)):
            s = AmbientEstimator(config).process(t, y[:, c])
            for j, x in enumerate(per_mode(s.frequency_hz, freqs)):
                single[c][j].extend(x)
        if with_peer:
            pe, pz, ends = peer(y, FRAME_FS, freqs)
            for j in range(len(freqs)):
                peer_err[j].extend(pe[j])
                peer_zeta[j].extend(pz[j])
                pairs = same_windows(t, e, j, freqs[j], ends[j], HOP_S)
                paired[j].extend((ours, pe[j][i]) for ours, i in pairs)
    print(
        '| mode | f (Hz) | joint: estimates | median err | RMS err | damping / true | MAC '
        '| pyOMA2 SSI-cov: windows | RMS err | damping / true | best single channel RMS err |'
    )
    print('|---|---|---|---|---|---|---|---|---|---|---|')
    for j, f in enumerate(freqs):
        err = np.array(joint['err'][j])
        best = min(
            ((rms(single[c][j]), c, len(single[c][j])) for c in range(len(single))),
            key=lambda x: (np.isnan(x[0]), x[0]),
        )
        pe = np.array(peer_err[j]) if with_peer else np.empty(0)
        pz = np.array(peer_zeta[j]) if with_peer else np.empty(0)
        print(
            f'| {j + 1} | {f:.3f} | {len(err)} | {100 * np.median(err):+.2f} % '
            f'| {100 * rms(err):.2f} % | {np.median(joint["zeta"][j]) / ZETA:.2f} '
            f'| {np.median(joint["mac"][j]):.4f} | {len(pe)} | {100 * rms(pe):.2f} % '
            f'| {np.median(pz) / ZETA if len(pz) else float("nan"):.2f} '
            f'| {100 * best[0]:.2f} % (s{best[1] + 1}, {best[2]} estimates) |'
        )
    if with_peer:
        print(
            "\nOn the same windows (the joint estimate whose 60 s window is the peer's, both "
            'found): RMS error joint / pyOMA2 (windows): '
            + ', '.join(
                f'mode {j + 1} {100 * rms([p[0] for p in pr]):.2f} / '
                f'{100 * rms([p[1] for p in pr]):.2f} % ({len(pr)})'
                for j, pr in enumerate(paired)
            )
        )


def invisible():
    config = EstimatorConfig(excitation='ambient', ambient_window_s=WINDOW_S)
    modes = [(1.0, 0.02, 1.0), (2.5, 0.02, 0.3), (4.0, 0.02, 1.0)]
    shapes = np.array([[1.0, 0.0, 0.6], [0.8, 0.0, -0.7], [0.5, 1.0, 0.9]])
    t, y = modal_record(400.0, 20.0, modes, shapes, 20.0, 3)
    r = AmbientEstimator(config, ['a', 'b', 'c']).process(t, y)
    print('\n## A mode invisible on channels a and b (2.5 Hz on c only), 3 channels, 20 Hz, 400 s')
    for (f, _, _), err in zip(modes, per_mode(r.estimates.frequency_hz, [m[0] for m in modes])):
        print(
            f'  {f:g} Hz: {len(err)} estimates, median error '
            + (f'{100 * np.median(err):+.2f} %' if len(err) else 'not found')
        )


def real_hct(real_data):
    hct = Path(real_data) / HCT_FILE
    if not hct.exists():
        print(f'\n(Heritage Court Tower record not found at {hct}: skipped)')
        return
    data = np.loadtxt(hct, delimiter=',', skiprows=1)
    t, y = data[:, 0], data[:, 1:]
    config = EstimatorConfig(excitation='ambient', ambient_window_s=120.0, band_hz=(0.5, 6.0))
    start = time.perf_counter()
    r = AmbientEstimator(config, [f'ch{i}' for i in range(1, 7)]).process(t, y)
    elapsed = time.perf_counter() - start
    f = r.estimates.frequency_hz
    rel = np.abs(f[:, None] / np.array(HCT_MODES)[None, :] - 1)
    idx, dist = np.argmin(rel, axis=1), np.min(rel, axis=1)
    found = [
        m for i, m in enumerate(HCT_MODES) if np.count_nonzero((idx == i) & (dist <= 0.02)) >= 10
    ]
    print('\n## Heritage Court Tower, 6 channels (40 Hz, 327.7 s), window 120 s, band 0.5-6 Hz')
    print(
        f'estimates {len(f)}; published modes found (>= 10 estimates within 2 %): '
        f'{len(found)} of 6 {found}; estimates > 2 % from every published mode: '
        f'{100 * np.mean(dist > 0.02):.1f} %; cost {t[-1] / elapsed:.0f}x real time'
    )
    for k in sorted(set(r.estimates.mode.tolist())):
        m = r.estimates.mode == k
        print(
            f'  mode {k}: {np.count_nonzero(m)} estimates, median {np.median(f[m]):.3f} Hz, '
            f'damping {100 * np.median(r.estimates.damping[m]):.2f} %, '
            f'median MAC with the previous window {np.nanmedian(r.mac[m]):.4f}'
        )


COST_MODES = [(3.0, 0.02, 1.0), (9.0, 0.01, 0.5), (21.0, 0.01, 0.3), (40.0, 0.005, 0.2)]


def cost_record(fs, duration, channels):
    rng = np.random.default_rng(7)
    shapes = rng.uniform(-1, 1, (channels, len(COST_MODES)))
    return modal_record(duration, fs, COST_MODES, shapes, 20.0, 8)


def cost(ref=None):
    fs, duration, channels = 500.0, 120.0, 8
    t, y = cost_record(fs, duration, channels)
    config = EstimatorConfig(excitation='ambient', ambient_window_s=30.0)
    names = [f'c{i}' for i in range(channels)]
    # warmed up and made before the clock starts, as reference_cost's probe does for --ref
    # (the first use designs the decimation filter, a few tenths of a second)
    AmbientEstimator(config, names).process(t[:2000], y[:2000])
    AmbientEstimator(config).process(t[:2000], y[:2000, 0])
    joint_est, one_est = AmbientEstimator(config, names), AmbientEstimator(config)
    start = time.process_time()  # CPU seconds: the steadier figure on a shared machine
    r = joint_est.process(t, y)
    joint = time.process_time() - start
    start = time.process_time()
    one_est.process(t, y[:, 0])
    one = time.process_time() - start
    print(f'\n## Cost: {channels} channels at {fs:g} Hz, {duration:g} s, window 30 s (batch)')
    print(
        f'joint {duration / joint:.0f}x real time ({len(r)} estimates); one channel through the '
        f'single-channel identifier, same run: {duration / one:.0f}x real time'
    )
    if ref:
        kw = {'excitation': 'ambient', 'ambient_window_s': 30.0}
        print(
            f'{ref.rev}, same records: joint {duration / ref.seconds(t, y, **kw):.0f}x, '
            f'one channel {duration / ref.seconds(t, y[:, 0], **kw):.0f}x real time'
        )
    stream(config)


def stream(config, fs=1000.0, duration=60.0, channels=6):
    """6 channels at 1 kHz through the joint identifier as a node feeds it."""
    t, y = cost_record(fs, duration, channels)
    names = [f'c{i}' for i in range(channels)]
    print(
        f'\n## {channels} channels at {fs:g} Hz, {duration:g} s, window 30 s, as a node feeds them'
    )
    est = AmbientEstimator(config, names)
    block = int(fs)
    worst, total = 0.0, 0.0
    for i in range(0, len(t), block):
        start = time.process_time()
        est.process(t[i : i + block], y[i : i + block])
        dt = time.process_time() - start
        worst, total = max(worst, dt), total + dt
    print(
        f'1 s blocks (process): {duration / total:.0f}x real time, '
        f'slowest block {1e3 * worst:.1f} ms'
    )
    est = AmbientEstimator(config, names)
    worst, total = 0.0, 0.0
    rows = y.tolist()
    for ti, yi in zip(t.tolist(), rows):
        start = time.process_time()
        est.update(ti, yi)
        dt = time.process_time() - start
        worst, total = max(worst, dt), total + dt
    print(
        f'sample by sample (update): {duration / total:.0f}x real time, '
        f'slowest sample {1e3 * worst:.1f} ms'
    )


def pluck(f, zeta, fs=500.0, seconds=6.0, phase=0.3):
    t = np.arange(int(seconds * fs)) / fs
    wn = 2 * np.pi * f
    return t, np.exp(-zeta * wn * t) * np.sin(wn * np.sqrt(1 - zeta**2) * t + phase)


def free_decays(seeds=10):
    names = ('a', 'b', 'c')
    shape = np.array([1.0, -0.6, 0.2])
    t, decay = pluck(5.0, 0.01)
    print(
        f'\n## Free decays: 5 Hz, zeta 1 %, shape (1, -0.6, 0.2), 3 channels, 500 Hz, 6 s, '
        f'noise 0.02, {seeds} seeds'
    )
    print('| configuration | joint: RMS error | RMS error/std | n | a alone | b alone | c alone |')
    print('|---|---|---|---|---|---|---|')
    configs = {
        'default': EstimatorConfig(),
        'model: damped-sinusoid': EstimatorConfig(model='damped-sinusoid'),
        'modes: 1': EstimatorConfig(modes=1),
    }
    for label, config in configs.items():
        joint, z, single = [], [], [[] for _ in names]
        for seed in range(seeds):
            rng = np.random.default_rng(seed)
            y = decay[:, None] * shape + 0.02 * rng.standard_normal((len(t), len(names)))
            est = create_estimator(config, names).process(t, y).estimates
            joint += list(est.frequency_hz / 5.0 - 1)
            z += list((est.frequency_hz - 5.0) / est.frequency_std_hz)
            for c in range(len(names)):
                alone = create_estimator(config).process(t, y[:, c]).frequency_hz
                single[c] += list(alone / 5.0 - 1)
        print(
            f'| {label} | {100 * rms(joint):.3f} % | {rms(z):.2f} | {len(joint)} | '
            + ' | '.join(f'{100 * rms(s):.3f} % ({len(s)})' for s in single)
            + ' |'
        )
    _, high = pluck(17.0, 0.005, phase=1.0)
    shapes = {5.0: np.array([1.0, 0.7, 0.0]), 17.0: np.array([0.0, 0.0, 1.0])}
    y = decay[:, None] * shapes[5.0] + 0.5 * high[:, None] * shapes[17.0]
    y += 0.01 * np.random.default_rng(4).standard_normal(y.shape)
    r = create_estimator(EstimatorConfig(modes=2), names).process(t, y)
    print('\n5 Hz on a and b only, 17 Hz on c only (modes: 2), noise 0.01:')
    for f, true in shapes.items():
        near = np.abs(r.estimates.frequency_hz / f - 1) < 0.02
        err = np.abs(r.estimates.frequency_hz[near] / f - 1)
        macs = [mac(s, true) for s in r.shapes[near]]
        print(
            f'  {f:g} Hz: {int(near.sum())} estimates, median error {100 * np.median(err):.3f} %, '
            f'median MAC {np.median(macs):.4f}'
        )
    off = len(r) - sum(
        int((np.abs(r.estimates.frequency_hz / f - 1) < 0.02).sum()) for f in shapes
    )
    print(f'  estimates > 2 % from both: {off} of {len(r)}')


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seeds', type=int, default=3)
    parser.add_argument('--no-peer', action='store_true')
    parser.add_argument('--real-data', default=str(REAL_DATA))
    parser.add_argument(
        '--ref', help="time this revision's identifiers beside (e.g. main; git archive)"
    )
    parser.add_argument('--cost-only', action='store_true', help='only the cost section')
    parser.add_argument('--free-only', action='store_true', help='only the free-decay section')
    args = parser.parse_args()
    # without pyOMA2 (left out on a Jazzy machine, or not loading) no peer column: one warning line
    args.no_peer = args.no_peer or optional('pyoma2') is None
    if args.free_only:
        free_decays()
        return
    ref = None
    if args.ref:
        from reference_cost import Reference  # benchmarks/

        ref = Reference(args.ref)
    if not args.cost_only:
        frame(args.seeds, not args.no_peer)
        invisible()
        real_hct(args.real_data)
        free_decays()
    cost(ref)


if __name__ == '__main__':
    main()
