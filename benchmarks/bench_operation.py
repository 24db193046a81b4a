# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""In operation (ambient excitation): this package's ``excitation = ambient`` vs SSI-cov of pyOMA2
vs the Whittle bound at the window used.

    .venv/bin/python benchmarks/bench_operation.py [--seeds 3] [--window 30] [--no-peer]
        [--real-data ../shared/real-data] [--real-only] [--arm-only] [--free-only] [--ref REV]
        [--default]

Synthetic records (``vib_estimator.sim.ambient``: white-noise-driven modes, 500 Hz, 180 s, the
estimates of the whole record, i.e. from the first full window on) and the real Heritage Court
Tower record (one channel, ``--band-hz 0.5 6`` -- the published modes' range -- and a 120 s
window; skipped if ../shared is absent). Per true mode: this package's RMS and median error,
share within 2 %, count beyond 5 %, damping median over the truth, RMS of error / its own
frequency std (calibration: 0.7-1.5 is the goal); the share of spurious estimates (> 10 % from
every mode); the Whittle bound (``core.whittle.whittle_std``, the asymptotic Cramer-Rao bound of a
noise-driven mode in white noise over the window's samples) and the RMS error over it; the peer
(pyOMA2 SSI-cov on consecutive 20 s windows, decimated to >= 4x the highest true frequency,
block rows 40, orders to 30, the pole nearest the true frequency at order 20:
``mpe(order_in=PEER_ORDER)`` -- told the frequencies, a generous peer) median error, share within
2 %, damping median ratio; and the cost as multiples of real time (record seconds per CPU
second; with ``--ref REV``, beside
that of revision REV's identifiers on the same records, same run: ``reference_cost``). Each driven
record is run
with ``excitation`` ambient and auto (a row each). Last, ``excitation = auto`` on the free-decay
benchmarks' records (bench_precision, bench_modes, the real beams): the share of ``excitation =
free``'s estimates it publishes unchanged, what it adds, and the seconds it judged driven
(``--free-only``: that section alone); with the paper's reproductions (``vib-estimator compare``'s
records) and the simulated arm moved every 10 s.

``--default`` (issue 37, item 6): the default -- no option, the configuration ``analyze``
decides from the record (``core.choice.decide``, applied by ``analysis.choosing.decided_config``)
-- beside ``--excitation ambient`` (the ``--window``) and the peer, on the synthetic records plus a
lightly damped 2 Hz mode (bench_defaults'), the arm under a random command and the arm free then
driven (:func:`free_then_driven`): per mode, the median error, RMS error / Whittle bound (at the
window each run used; synthetic records), RMS of error / std, within 2 %, beyond 5 %; on the
arm free then driven also the peer's windows of the driven stretch alone.
"""

from __future__ import annotations

import argparse
import itertools
import logging
import math
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from vib_estimator.core import EstimatorConfig, create_estimator
from vib_estimator.core.whittle import whittle_std
from vib_estimator.extras import optional
from vib_estimator.sim.ambient import ambient_record

warnings.filterwarnings('ignore', category=RuntimeWarning)  # pyOMA2's np.cov on one channel
os.environ.setdefault('TQDM_DISABLE', '1')  # pyOMA2's progress bars
logging.disable(logging.WARNING)  # pyOMA2's INFO/WARNING chatter
FS = 500.0
DURATION = 180.0
#: name -> (modes [(f Hz, zeta, variance)], SNR dB)
CASES = {
    '1 mode 5 Hz, zeta 1 %, 26 dB': ([(5.0, 0.01, 1.0)], 26.0),
    '1 mode 5 Hz, zeta 0.2 %, 30 dB': ([(5.0, 0.002, 1.0)], 30.0),
    '5 + 17 Hz, zeta 1 / 0.5 %, 20 dB': ([(5.0, 0.01, 1.0), (17.0, 0.005, 0.3)], 20.0),
    '3 + 11 + 23 Hz, zeta 2 / 1 / 0.5 %, 25 dB': (
        [(3.0, 0.02, 1.0), (11.0, 0.01, 0.5), (23.0, 0.005, 0.2)],
        25.0,
    ),
    'close pair 8 / 8.8 Hz, zeta 1 %, 26 dB': ([(8.0, 0.01, 1.0), (8.8, 0.01, 0.8)], 26.0),
}
REAL_DATA = Path(__file__).resolve().parents[2] / 'shared' / 'real-data'
HCT_FILE = Path('heritage_court_tower') / 'hct_setup1.csv'
#: this package's excitations benchmarked on the driven records (a row each)
EXCITATIONS = ('ambient', 'auto')
HCT_MODES = (1.23, 1.29, 1.45, 3.85, 4.26, 5.35)
#: ``--default``'s records beyond :data:`CASES`: a lightly damped 2 Hz mode (bench_defaults')
DEFAULT_CASES = {**CASES, '1 mode 2 Hz, zeta 0.2 %, 20 dB': ([(2.0, 0.002, 1.0)], 20.0)}
#: :func:`free_then_driven`: the seconds the arm rings freely before the random command
FREE_S = 40.0
PEER_WINDOW_S = 20.0
PEER_ORDER = 20
#: hard criteria: damping < 20 %; the mode-shape ones (MPC, MPD) mean nothing with one channel
PEER_HC = {'xi_max': 0.2, 'mpc_lim': None, 'mpd_lim': None, 'CoV_max': None}


def ssi_cov_window(data, fs, freqs, rows):
    """pyOMA2 SSI-cov of one window ``data`` (samples x channels): block rows ``rows``, orders to
    30, the poles nearest ``freqs`` at order :data:`PEER_ORDER` (told the frequencies): ``(Fn,
    Xi)`` flat, or None when pyOMA2 finds none."""
    from pyoma2.algorithms import SSI
    from pyoma2.setup import SingleSetup

    setup = SingleSetup(data, fs)
    algo = SSI(name='cov', method='cov', br=rows, ordmax=30, calc_unc=False, hc=PEER_HC)
    setup.add_algorithms(algo)
    setup.run_by_name('cov')
    try:
        setup.mpe('cov', sel_freq=list(freqs), order_in=PEER_ORDER)
    except Exception:  # noqa: BLE001 -- pyOMA2 raises plain errors (mode absent)
        return None
    return np.ravel(algo.result.Fn), np.ravel(algo.result.Xi)


def peer_ssi(t, y, fs, freqs):
    """pyOMA2 SSI-cov on consecutive 20 s windows: {true frequency: [(f, zeta)]}."""
    from scipy.signal import decimate

    q = max(1, int(fs // (4 * max(freqs))))
    out = {f: [] for f in freqs}
    n = int(PEER_WINDOW_S * fs)
    for start in range(0, len(y) - n + 1, n):
        seg = y[start : start + n]
        if q > 1:
            seg = decimate(seg, q, ftype='fir', zero_phase=True)
        res = ssi_cov_window(seg[:, None], fs / q, freqs, 40)
        if res is None:
            continue
        for f, fn, xi in zip(freqs, *res):
            if np.isfinite(fn):
                out[f].append((float(fn), float(xi)))
    return out


def ours(t, y, config):
    """The estimates and the CPU seconds they took (the machine is shared: CPU time is the
    steadier figure)."""
    est = create_estimator(config)
    start = time.process_time()
    e = est.process(t, y)
    return e, time.process_time() - start


def assign(freq, truth):
    """Index of the nearest true mode and the relative distance to it."""
    rel = np.abs(freq[:, None] / np.asarray(truth)[None, :] - 1)
    return np.argmin(rel, axis=1), np.min(rel, axis=1)


def synthetic(seeds, window, peer, ref=None):
    n_window = int(window * FS) + 1
    print(f'## Synthetic records: {FS:g} Hz, {DURATION:g} s, {seeds} seeds, window {window:g} s')
    print(
        '| record | mode | Whittle bound | RMS err (x bound) | median err | within 2 % | > 5 % '
        '| damping med / true | RMS err/std | SSI-cov (pyOMA2) median / within 2 % / damping '
        '| spurious | cost (x real time) |' + (f' cost of {ref.rev} |' if ref else '')
    )
    print('|---|---|---|---|---|---|---|---|---|---|---|---|' + ('---|' if ref else ''))
    for (name, (modes, snr)), excitation in itertools.product(CASES.items(), EXCITATIONS):
        config = EstimatorConfig(excitation=excitation, ambient_window_s=window)
        run_peer = peer and excitation == 'ambient'  # the peer does not change with ours
        truth = [m[0] for m in modes]
        err = {k: [] for k in range(len(modes))}
        zs = {k: [] for k in range(len(modes))}
        cal = {k: [] for k in range(len(modes))}
        peer_err = {k: [] for k in range(len(modes))}
        peer_z = {k: [] for k in range(len(modes))}
        spurious = total = 0
        cost = ref_cost = 0.0
        noise_var = None
        for seed in range(seeds):
            t, y, noise_var = ambient_record(DURATION, FS, modes, snr, seed)
            e, elapsed = ours(t, y, config)
            cost += elapsed
            if ref:
                ref_cost += ref.seconds(t, y, excitation=excitation, ambient_window_s=window)
            idx, dist = assign(e.frequency_hz, truth)
            total += len(e)
            spurious += int(np.count_nonzero(dist > 0.10))
            for k in range(len(modes)):
                m = (idx == k) & (dist <= 0.10)
                rel = e.frequency_hz[m] / truth[k] - 1
                err[k].extend(rel)
                zs[k].extend(e.damping[m])
                cal[k].extend((e.frequency_hz[m] - truth[k]) / e.frequency_std_hz[m])
            if run_peer:
                for k, (f, vals) in enumerate(peer_ssi(t, y, FS, truth).items()):
                    peer_err[k].extend(abs(v[0] / f - 1) for v in vals)
                    peer_z[k].extend(v[1] for v in vals)
        bounds = whittle_std(modes, noise_var, FS, n_window)
        for k, (f, z, _) in enumerate(modes):
            a = np.abs(np.array(err[k]))
            bound = bounds[k][0] / f
            rms = math.sqrt(np.mean(a**2)) if len(a) else math.nan
            pe = np.array(peer_err[k])
            peer_txt = (
                (
                    f'{100 * np.median(pe):.2f} % / {100 * np.mean(pe <= 0.02):.0f} % / '
                    f'{np.median(peer_z[k]) / z:.2f}'
                )
                if len(pe)
                else 'n/a'
                if excitation == 'ambient'
                else 'as above'
            )
            print(
                f'| {f"{name}, {excitation}" if k == 0 else ""} | {f:g} Hz | '
                f'{100 * bound:.2f} % | '
                f'{100 * rms:.2f} % ({rms / bound:.2f}) | {100 * np.median(a):.2f} % | '
                f'{100 * np.mean(a <= 0.02):.1f} % | {int(np.count_nonzero(a > 0.05))} | '
                f'{np.nanmedian(zs[k]) / z:.2f} | {math.sqrt(np.mean(np.square(cal[k]))):.2f} | '
                f'{peer_txt} | '
                f'{(f"{100 * spurious / max(total, 1):.1f} % of {total}") if k == 0 else ""} | '
                f'{(f"{seeds * DURATION / cost:.0f}") if k == 0 else ""} |'
                + (f' {(f"{seeds * DURATION / ref_cost:.0f}") if k == 0 else ""} |' if ref else '')
            )
        sys.stdout.flush()


def arm(seeds, window):
    """The simulated arm (Eqs. 19-23, 45.55 g: 1.33 Hz, zeta 0.4 %) never at rest."""
    from vib_estimator.sim.arm_model import simulate_driven

    print(
        f'\n## Simulated arm under continuous motion (coupling torque, 500 Hz, {DURATION:g} s, '
        f'{seeds} seeds, window {window:g} s)'
    )
    print(
        '| excitation | true f | median err | RMS err | within 2 % | > 5 % | spurious | '
        'damping med / true | RMS err/std | estimates |'
    )
    print('|---|---|---|---|---|---|---|---|---|---|')
    drives = (('random', 0.3), ('ambient', 0.02))
    for (excitation, level), ours_excitation in itertools.product(drives, EXCITATIONS):
        config = EstimatorConfig(excitation=ours_excitation, ambient_window_s=window)
        rel, zs, cal, n_spur, n = [], [], [], 0, 0
        for seed in range(seeds):
            rec = simulate_driven(DURATION, excitation, level, seed=seed)
            e, _ = ours(rec.t, rec.torque, config)
            f0 = float(rec.f_true[0])
            err = e.frequency_hz / f0 - 1
            n += len(e)
            n_spur += int(np.count_nonzero(np.abs(err) > 0.10))
            m = np.abs(err) <= 0.10
            rel.extend(err[m])
            zs.extend(e.damping[m])
            cal.extend((e.frequency_hz[m] - f0) / e.frequency_std_hz[m])
        a = np.abs(np.array(rel))
        print(
            f'| {excitation} (level {level:g}), {ours_excitation} | {f0:.4f} Hz | '
            f'{100 * np.median(a):.2f} % | '
            f'{100 * math.sqrt(np.mean(a**2)):.2f} % | {100 * np.mean(a <= 0.02):.1f} % | '
            f'{int(np.count_nonzero(a > 0.05))} | {100 * n_spur / max(n, 1):.1f} % | '
            f'{np.nanmedian(zs) / 0.004:.2f} | {math.sqrt(np.mean(np.square(cal))):.2f} | {n} |'
        )
        sys.stdout.flush()


def real_hct(peer, real_data, ref=None):
    hct = Path(real_data) / HCT_FILE
    if not hct.exists():
        print(f'\n(Heritage Court Tower record not found at {hct}: skipped)')
        return
    data = np.loadtxt(hct, delimiter=',', skiprows=1)
    t, y = data[:, 0], data[:, 2]  # ch2
    config = EstimatorConfig(excitation='ambient', ambient_window_s=120.0, band_hz=(0.5, 6.0))
    e, elapsed = ours(t, y, config)
    ref_txt = ''
    if ref:
        sec = ref.seconds(t, y, excitation='ambient', ambient_window_s=120.0, band_hz=(0.5, 6.0))
        ref_txt = f' ({ref.rev}: {t[-1] / sec:.0f}x)'
    idx, dist = assign(e.frequency_hz, HCT_MODES)
    found = sorted(
        {
            HCT_MODES[i]
            for i in set(idx[dist <= 0.02])
            if np.count_nonzero((idx == i) & (dist <= 0.02)) >= 10
        }
    )
    print('\n## Heritage Court Tower, ch2 (40 Hz, 327.7 s), window 120 s, band 0.5-6 Hz')
    print(
        f'estimates {len(e)}; published modes found (>= 10 estimates within 2 %): {found}; '
        f'estimates > 2 % from every published mode: {100 * np.mean(dist > 0.02):.1f} %; '
        f'cost {t[-1] / elapsed:.0f}x real time{ref_txt}'
    )
    for k in sorted(set(e.mode)):
        m = e.mode == k
        print(
            f'  mode {k}: {np.count_nonzero(m)} estimates, '
            f'median {np.median(e.frequency_hz[m]):.3f} Hz, '
            f'damping {100 * np.median(e.damping[m]):.2f} %, '
            f'median std {np.median(e.frequency_std_hz[m]):.4f} Hz'
        )
    if peer:
        from pyoma2.algorithms import SSI
        from pyoma2.setup import SingleSetup

        setup = SingleSetup(y[:, None], 40.0)
        algo = SSI(name='cov', method='cov', br=60, ordmax=40, calc_unc=False, hc=PEER_HC)
        setup.add_algorithms(algo)
        setup.run_by_name('cov')
        setup.mpe('cov', sel_freq=list(HCT_MODES), order_in=PEER_ORDER)
        fn = np.ravel(algo.result.Fn)
        print(
            '  SSI-cov (pyOMA2, whole record, told the published frequencies): '
            + ', '.join(f'{f:.3f}' for f in fn)
        )


def free_decays(real_data):
    """excitation auto on the free-decay benchmarks' records: the share of excitation free's
    estimates it publishes unchanged (same t, frequency, damping, std) and what it adds."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from bench_modes import CASES as MODE_CASES
    from bench_modes import CONFIG as MODE_CONFIG
    from bench_modes import decay
    from bench_precision import AMP, records
    from bench_precision import CASES as PRECISION_CASES
    from real_data import REFERENCE

    from vib_estimator.analysis.compare import CASES as COMPARE_CASES
    from vib_estimator.io.csv_reader import read_csv_series
    from vib_estimator.sim.arm_model import Move, simulate

    def runs():
        for label, (model, zeta, offset, band) in PRECISION_CASES.items():
            cfg = EstimatorConfig.paper(model=model, band_hz=band)
            sd = AMP / math.sqrt(2 * 10 ** (40 / 20))
            for periods in (0.5, 2.0, 20.0):
                recs = [(t, y) for t, y, _, _ in records(zeta, offset, sd, periods, 1)]
                yield (
                    f'bench_precision {label}, {periods:g} periods',
                    cfg.replace(min_periods=periods),
                    recs,
                )
        for label, (freqs, amps, zetas, clip) in MODE_CASES.items():
            recs = [decay(freqs, amps, zetas, clip, seed) for seed in range(3)]
            yield f'bench_modes {label}', MODE_CONFIG, recs
        sched = (Move(0.0, 1.0, 1.0, 0.030), Move(12.0, 0.0, 1.0, 0.06117))
        rec = simulate(24.0, sched)
        yield 'bench_modes tip-mass change (arm)', MODE_CONFIG, [(rec.t, rec.torque)]
        # the paper's reproductions (vib-estimator compare: Fig. 1's sine, Sections 5.3 and 5.5's
        # arm) and the arm moved every 10 s, from rest and while it rings (1.15-1.64 Hz: several
        # periods to an envelope block)
        moves = (Move(0.0, 1.0, 1.0), Move(10.0, 0.0, 1.0), Move(20.0, 0.5, 0.5), Move(30.0, 1.2))

        def moved(seed):
            rec = simulate(40.0, moves, seed=seed)
            return rec.t, rec.torque

        configs = (('paper', EstimatorConfig.paper()), ('defaults', EstimatorConfig()))
        arm_records = [(f'compare {c.key} ({c.title})', c.record) for c in COMPARE_CASES]
        arm_records.append(('arm moved every 10 s', moved))
        for label, record in arm_records:
            recs = [record(seed)[:2] for seed in range(3)]
            for name, cfg in configs:
                yield f'{label}, {name}', cfg, recs
        folder = Path(real_data) / 'aluminium_cantilever_adxl357'
        if folder.is_dir():
            for length in REFERENCE:
                s = read_csv_series(folder / f'{length}cm_uniform_1000Hz.csv')
                for name, cfg in (('defaults', EstimatorConfig()), ('modes 3', MODE_CONFIG)):
                    yield f'real beam {length} cm, {name}', cfg, [(s.t, s.y)]

    print('\n## Free decays: excitation auto against free on the free-decay benchmarks')
    print('| records | free estimates | published unchanged by auto | added by auto | driven s |')
    print('|---|---|---|---|---|')
    for label, cfg, recs in runs():
        n_free = same = added = 0
        driven = 0.0
        for t, y in recs:
            free = create_estimator(cfg.replace(excitation='free')).process(t, y)
            auto = create_estimator(cfg.replace(excitation='auto'))
            e = auto.process(t, y)
            key = lambda a: set(  # noqa: E731
                map(repr, zip(a.t.tolist(), a.frequency_hz.tolist(), a.damping.tolist()))
            )
            kf, ka = key(free), key(e)
            n_free += len(kf)
            same += len(kf & ka)
            added += len(ka - kf)
            driven += auto.driven_s
        print(
            f'| {label} ({len(recs)}) | {n_free} | {100 * same / max(n_free, 1):.1f} % | '
            f'{added} | {driven:.0f} |'
        )
        sys.stdout.flush()


def free_then_driven(seed):
    """The arm (45.55 g, 1.33 Hz) moved to 1 rad and back (0-4 s), ringing freely, then under a
    random command (level 0.3, as :func:`arm`'s) from :data:`FREE_S` s to :data:`DURATION`:
    ``(t, y, f)``."""
    from vib_estimator.sim.arm_model import DrivenArmSimulator, Move

    sim = DrivenArmSimulator(
        rate_hz=FS,
        seed=seed,
        schedule=(Move(0.0, 1.0, 1.0), Move(3.0, 0.0, 1.0)),
        excitation='moves',
        level=0.3,
    )
    rows = []
    for k in range(int(round(DURATION * FS))):
        if k == int(round(FREE_S * FS)):
            sim.excitation = 'random'
        rows.append(sim.step())
    rows = np.array(rows)
    return rows[:, 0], rows[:, 1], float(rows[0, 2])


def default_runs(t, y, window):
    """(label, configuration) of ``--default``: the default as ``analyze`` decides it from the
    record, and ``--excitation ambient`` with the ``window``."""
    from vib_estimator.analysis.choosing import decided_config
    from vib_estimator.core.choice import decide

    base = EstimatorConfig()
    config, _ = decided_config(base, decide(t, y, 1, base.ambient_window_s), 'analyze')
    what = f'{config.excitation}' + (
        f' {config.ambient_window_s:.0f} s' if config.excitation != 'free' else ''
    )
    return (
        (f'default ({what})', config),
        (f'ambient ({window:g} s)', base.replace(excitation='ambient', ambient_window_s=window)),
    )


def defaults(seeds, window, peer):
    """``--default``: module doc."""
    from vib_estimator.sim.arm_model import simulate_driven

    def arm_random(seed):
        rec = simulate_driven(DURATION, 'random', 0.3, seed=seed)
        return rec.t, rec.torque, None, [float(rec.f_true[0])]

    def arm_mixed(seed):
        t, y, f = free_then_driven(seed)
        return t, y, None, [f]

    def synthetic_record(modes, snr):
        def make(seed):
            t, y, noise_var = ambient_record(DURATION, FS, modes, snr, seed)
            return t, y, noise_var, [m[0] for m in modes]

        return make

    cases = [
        (name, modes, synthetic_record(modes, snr)) for name, (modes, snr) in DEFAULT_CASES.items()
    ]
    arm_mode = [(1.3306, 0.004, 1.0)]
    cases.append(('arm, random command (level 0.3)', arm_mode, arm_random))
    cases.append((f'arm, free {FREE_S:g} s then a random command', arm_mode, arm_mixed))
    print(
        f'\n## The default (no option) beside --excitation ambient ({window:g} s) and the peer: '
        f'{FS:g} Hz, {DURATION:g} s, {seeds} seeds'
    )
    print(
        '| record | configuration | mode | median err | RMS err / bound | RMS err/std '
        '| within 2 % | > 5 % | estimates |'
    )
    print('|---|---|---|---|---|---|---|---|---|')
    for name, modes, make in cases:
        rows = {}
        peer_err = {k: [] for k in range(len(modes))}
        peer_driven = {k: [] for k in range(len(modes))}
        for seed in range(seeds):
            t, y, noise_var, truth = make(seed)
            for label, config in default_runs(t, y, window):
                key = label.split(' (')[0]
                row = rows.setdefault(
                    key, {'labels': [], 'n': 0, 'err': {}, 'norm': {}, 'cal': {}}
                )
                row['labels'].append(label.split(' (')[1][:-1] if '(' in label else '')
                e, _ = ours(t, y, config)
                row['n'] += len(e)
                idx, dist = assign(e.frequency_hz, truth)
                bounds = None
                if noise_var is not None and config.excitation != 'free':
                    n_window = int(config.ambient_window_s * FS) + 1
                    bounds = whittle_std(modes, noise_var, FS, n_window)
                for k, f in enumerate(truth):
                    m = (idx == k) & (dist <= 0.10)
                    rel = e.frequency_hz[m] / f - 1
                    row['err'].setdefault(k, []).extend(rel)
                    row['cal'].setdefault(k, []).extend(
                        (e.frequency_hz[m] - f) / e.frequency_std_hz[m]
                    )
                    if bounds is not None:
                        row['norm'].setdefault(k, []).extend(rel / (bounds[k][0] / f))
            if peer:
                for k, (f, vals) in enumerate(peer_ssi(t, y, FS, truth).items()):
                    peer_err[k].extend(v[0] / f - 1 for v in vals)
                if make is arm_mixed:  # the peer's driven windows alone (no free decay in them)
                    after = t >= FREE_S
                    for k, (f, vals) in enumerate(peer_ssi(t[after], y[after], FS, truth).items()):
                        peer_driven[k].extend(v[0] / f - 1 for v in vals)
        for key, row in rows.items():
            what = sorted(set(row['labels']))
            label = key + (f' ({" / ".join(what)})' if what != [''] else '')
            for k, f in enumerate(truth):
                print(
                    default_row(
                        name if k == 0 and key == 'default' else '',
                        label if k == 0 else '',
                        f,
                        row['err'].get(k, []),
                        row['norm'].get(k, []),
                        row['cal'].get(k, []),
                        row['n'] if k == 0 else None,
                    )
                )
        if peer:
            for k, f in enumerate(truth):
                label = f'SSI-cov (pyOMA2) {PEER_WINDOW_S:g} s' if k == 0 else ''
                print(default_row('', label, f, peer_err[k], [], [], None))
            for k, f in enumerate(truth if peer_driven[0] else ()):
                label = f'SSI-cov, the windows from {FREE_S:g} s' if k == 0 else ''
                print(default_row('', label, f, peer_driven[k], [], [], None))
        sys.stdout.flush()


def default_row(name, label, f, err, norm, cal, n):
    """One row of :func:`defaults`' table."""
    a = np.abs(np.asarray(err, dtype=float))
    if not len(a):
        return f'| {name} | {label} | {f:g} Hz | none | | | | | {"" if n is None else n} |'
    rms_norm = f'{math.sqrt(np.mean(np.square(norm))):.2f}' if len(norm) else '-'
    rms_cal = f'{math.sqrt(np.mean(np.square(cal))):.2f}' if len(cal) else '-'
    return (
        f'| {name} | {label} | {f:g} Hz | {100 * np.median(a):.3f} % | {rms_norm} | {rms_cal} | '
        f'{100 * np.mean(a <= 0.02):.1f} % | {int(np.count_nonzero(a > 0.05))} | '
        f'{"" if n is None else n} |'
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seeds', type=int, default=3)
    parser.add_argument('--window', type=float, default=30.0)
    parser.add_argument('--no-peer', action='store_true')
    parser.add_argument(
        '--real-data',
        default=str(REAL_DATA),
        help='the shared real-data folder (default ../shared/real-data)',
    )
    parser.add_argument('--real-only', action='store_true', help='only the real record')
    parser.add_argument('--arm-only', action='store_true', help='only the simulated arm')
    parser.add_argument(
        '--free-only', action='store_true', help='only excitation auto on the free decays'
    )
    parser.add_argument(
        '--ref', help="time this revision's identifiers beside (e.g. main; git archive)"
    )
    parser.add_argument(
        '--default',
        action='store_true',
        help='only the default (decided from the record) beside ambient and the peer',
    )
    args = parser.parse_args()
    # without pyOMA2 (left out on a Jazzy machine, or not loading) no peer column: one warning line
    args.no_peer = args.no_peer or optional('pyoma2') is None
    ref = None
    if args.ref:
        from reference_cost import Reference  # benchmarks/

        ref = Reference(args.ref)
    if args.default:
        defaults(args.seeds, args.window, not args.no_peer)
        return
    if args.free_only:
        free_decays(args.real_data)
        return
    if args.arm_only:
        arm(args.seeds, args.window)
        return
    if not args.real_only:
        synthetic(args.seeds, args.window, not args.no_peer, ref)
        arm(args.seeds, args.window)
    real_hct(not args.no_peer, args.real_data, ref)
    free_decays(args.real_data)


if __name__ == '__main__':
    main()
