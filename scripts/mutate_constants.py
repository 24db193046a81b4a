#!/usr/bin/env python3
# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Are the tuning constants pinned? Mutate each to 0.001x and 1000x, see whether a test fails.

    python scripts/mutate_constants.py [--sample N] [--seed S] [--only NAME ...] [--list]
                                       [--full] [--tests FILE ...] [--timeout SECONDS]

A tuning constant is pinned when setting it to 0.001x makes a test fail and setting it to 1000x
makes a test fail (docs/testing.md, issue 38). The population is every module-level UPPER_CASE
numeric constant (a number, or a tuple of numbers) of ``vib_estimator/core`` and of the analysis
modules with heuristics (:data:`MODULES`), less the structural ones (:data:`STRUCTURAL`: array
layouts, sizes, names, versions, mathematical constants, the warm-up signal), each listed with its
reason. ``--list`` prints the population; ``--sample N --seed S`` draws N of it (seeded, the
measure of issue 38); ``--only`` names constants (``MODULE.NAME`` or ``NAME``).

Each mutant is written into a copy of the tree in a temporary folder (the working tree is never
edited): a float becomes ``v * factor``, an int ``round(v * factor)`` (0.001x of a small count
is 0), a tuple each of its numbers; a constant equal to 0 becomes -1000 (low) and 1000 (high). The
copy's numba cache of the mutated module and of every compiled module that imports it (numba does
not track a callee's or a constant's module) is deleted, then the mutant runs the test files of its
module (:data:`TESTS`; ``--full``: all of test/core and test/analysis) with ``pytest -x``. A mutant
is caught when a test fails or errors (or the run exceeds ``--timeout``: "timeout", counted as
caught, as mutation tools do, and marked in the table). The table gives, per constant, each
mutant's outcome and the first test that caught it; the last line the fraction pinned both sides.
"""

from __future__ import annotations

import argparse
import ast
import importlib
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = 'vib_estimator'

#: the modules whose constants are mutated (package-relative paths)
MODULES = tuple(
    f'core/{m}.py'
    for m in (
        'ambient',
        'auto',
        'choice',
        'config',
        'correlations',
        'estimator',
        'health_model',
        'identity',
        'kernel',
        'modes',
        'multichannel_free',
        'ssi',
        'subspace',
        'uncertainty',
        'warmup',
        'whittle',
    )
) + ('analysis/choosing.py', 'analysis/summary.py')

#: the test files most likely to catch a mutant of each module (the fast mapping)
TESTS = {
    'ambient': [
        'test/core/test_ambient.py',
        'test/core/test_ambient_incremental.py',
        'test/core/test_whittle_refinement.py',
        'test/analysis/test_choosing.py',  # a window too short for the identifier, said
    ],
    'auto': ['test/core/test_auto.py', 'test/core/test_choice.py'],  # choice reads its envelope
    'choice': [
        'test/core/test_choice.py',
        'test/analysis/test_choosing.py',
        'test/nodes/test_stream.py',  # the node's decisions (StreamChoice)
    ],
    'config': ['test/core/test_estimator.py'],
    'correlations': ['test/core/test_ambient_incremental.py', 'test/core/test_ambient.py'],
    'estimator': [
        'test/core/test_estimator.py',
        'test/core/test_bad_input.py',
        'test/core/test_multichannel.py',
        'test/analysis/test_channels.py',
    ],
    'health_model': ['test/core/test_health_model.py'],
    'identity': [
        'test/core/test_identity.py',
        'test/core/test_ambient.py',
        'test/core/test_auto.py',
    ],
    'kernel': [
        'test/core/test_estimator.py',
        'test/core/test_bad_input.py',
        'test/core/test_kernel_reference.py',
        'test/core/test_precision.py',
        'test/core/test_kernel_early.py',  # the long window's start: onsets, releases, stalls
    ],
    'modes': [
        'test/core/test_modes.py',
        'test/core/test_subspace.py',
    ],
    'multichannel_free': [
        'test/core/test_multichannel_free.py',
    ],
    'ssi': ['test/core/test_ambient.py', 'test/core/test_multichannel.py'],
    'subspace': ['test/core/test_subspace.py', 'test/core/test_modes.py'],
    'uncertainty': [
        'test/core/test_estimator.py',
        'test/core/test_precision.py',
        'test/core/test_kernel_reference.py',
    ],
    'warmup': ['test/nodes/test_warmup.py'],
    'whittle': ['test/core/test_whittle_refinement.py', 'test/core/test_ambient.py'],
    'choosing': ['test/analysis/test_choosing.py'],
    'summary': ['test/analysis/test_summary.py'],
}

#: constants that are not tuning: what they are (name or regular expression -> reason)
STRUCTURAL = {
    r'[SBIFR]_[A-Z0-9_]+|N_[A-Z]+|N_STATE_FIXED|DEC_N|ROOM': 'array layout (offsets, slot counts)',
    r'NH|NBJ|NS|NQ|NLEV|KMAX|PCOL|NPEND': 'array sizes fixed by the method or a parameter range',
    r'BINOMIAL|BAND_DAMPING|TWO_PI|INF|MAD_TO_STD': (
        "mathematical constants (Butterworth poles, binomials, a normal sample's std per MAD)"
    ),
    r'VERSION': 'file-format version',
    r'MODEL_[A-Z]+': 'enumeration',
    r'RATE_HZ|TONE_HZ|SAMPLES': 'warm-up signal: compiles the kernels, its output is discarded',
    r'MAX_STAMP_S|MAX_ABS_VALUE': 'input-validity limits (bad-input contract, not a heuristic)',
    r'PRODUCT_BLOCK': (
        'a work block size (rows of lag products computed at once): the correlations are the same '
        'at any value but for rounding (test_sliding_lag_products_equal_the_batch_correlations), '
        'only memory and speed depend on it'
    ),
}


@dataclass(frozen=True)
class Constant:
    module: str  # package-relative path, e.g. core/auto.py
    name: str
    value: object
    line: int

    @property
    def key(self) -> str:
        return f'{Path(self.module).stem}.{self.name}'


def _numeric(value) -> bool:
    if isinstance(value, bool):
        return False
    if isinstance(value, (int, float)):
        return True
    return isinstance(value, tuple) and len(value) > 0 and all(_numeric(v) for v in value)


def structural(name: str) -> str | None:
    """The reason ``name`` is not a tuning constant, or None."""
    for pattern, reason in STRUCTURAL.items():
        if re.fullmatch(pattern, name.lstrip('_')):
            return reason
    return None


def constants(root: Path = ROOT) -> tuple[list[Constant], list[tuple[Constant, str]]]:
    """(tuning constants, [(structural constant, reason)]) of :data:`MODULES`, in file order."""
    sys.path.insert(0, str(root))
    tuning, skipped = [], []
    for rel in MODULES:
        path = root / PACKAGE / rel
        module = importlib.import_module(f'{PACKAGE}.{rel[:-3].replace("/", ".")}')
        for node in ast.parse(path.read_text()).body:
            target = _target(node)
            if target is None or not re.fullmatch(r'_?[A-Z][A-Z0-9_]*', target):
                continue
            value = getattr(module, target, None)
            if not _numeric(value):
                continue
            c = Constant(rel, target, value, node.lineno)
            reason = structural(target)
            (skipped.append((c, reason)) if reason else tuning.append(c))
    sys.path.remove(str(root))
    return tuning, skipped


def _target(node) -> str | None:
    if isinstance(node, ast.Assign) and len(node.targets) == 1:
        target = node.targets[0]
    elif isinstance(node, ast.AnnAssign) and node.value is not None:
        target = node.target
    else:
        return None
    return target.id if isinstance(target, ast.Name) else None


def mutant_value(value, factor: float):
    """``value`` scaled by ``factor`` (ints rounded; 0 -> -1000 or 1000; tuples element-wise)."""
    if isinstance(value, tuple):
        return tuple(mutant_value(v, factor) for v in value)
    if value == 0:
        return type(value)(-1000 if factor < 1 else 1000)
    if isinstance(value, int):
        return int(round(value * factor))
    return value * factor


def mutate_source(text: str, name: str, new) -> str:
    """``text`` with the module-level assignment of ``name`` given the value ``new``."""
    lines = text.splitlines(keepends=True)
    for node in ast.parse(text).body:
        if _target(node) == name:
            v = node.value
            start = sum(len(x) for x in lines[: v.lineno - 1]) + _byte_col(
                lines[v.lineno - 1], v.col_offset
            )
            end = sum(len(x) for x in lines[: v.end_lineno - 1]) + _byte_col(
                lines[v.end_lineno - 1], v.end_col_offset
            )
            return text[:start] + repr(new) + text[end:]
    raise KeyError(name)


def _byte_col(line: str, offset: int) -> int:
    """ast's column offsets count UTF-8 bytes: the character index."""
    return len(line.encode()[:offset].decode())


def compiled_importers(root: Path, module: str) -> set[str]:
    """``module`` (a stem) and the modules of core/analysis that import it, transitively."""
    imports = {}
    for path in (root / PACKAGE).glob('*/*.py'):
        text = path.read_text()
        imports[path.stem] = set(
            re.findall(r'from \.+(?:core\.)?(\w+) import|from \. import (\w+)', text)
        )
        imports[path.stem] = {a or b for a, b in imports[path.stem]}
    found, todo = {module}, [module]
    while todo:
        m = todo.pop()
        for stem, deps in imports.items():
            if m in deps and stem not in found:
                found.add(stem)
                todo.append(stem)
    return found


def drop_numba_cache(root: Path, stems: set[str]) -> None:
    for cache in (root / PACKAGE).glob('*/__pycache__/*.nb[ic]'):
        if cache.name.split('.')[0] in stems:
            cache.unlink()


def run_tests(root: Path, tests: list[str], timeout: float) -> tuple[str, str]:
    """('pass' | 'fail' | 'timeout', the first failing test or '')."""
    env = dict(os.environ, PYTHONPATH=str(root))
    env.pop('NUMBA_CACHE_DIR', None)  # the copy's own __pycache__
    tests = [t for t in tests if (root / t).exists()]
    cmd = [sys.executable, '-m', 'pytest', '-x', '-q', '-rfE', '-p', 'no:cacheprovider', *tests]
    # its own process group: a timeout ends the processes its tests started too (a test's
    # subprocess outlived a killed pytest, its folder deleted under it)
    proc = subprocess.Popen(
        cmd,
        cwd=root,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        start_new_session=True,
    )
    try:
        out = proc.communicate(timeout=timeout)[0]
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        return 'timeout', ''
    hit = re.search(r'^(?:FAILED|ERROR) (\S+)', out, re.M)
    if hit:
        return 'fail', hit.group(1)
    if re.search(r'\b\d+ passed\b', out) and not re.search(r'\b(failed|error)', out):
        return 'pass', ''
    return 'fail', out.strip().splitlines()[-1] if out.strip() else 'no output'


def tautologies(root: Path, names: set[str]) -> list[str]:
    """Test lines that assert a constant's value (``assert X.NAME == 2.0``): they catch every
    mutant of it without checking a behaviour, so they defeat the measure."""
    pattern = re.compile(r'assert\b.*\b(' + '|'.join(sorted(names)) + r')\b\)?\s*==')
    found = []
    for path in sorted((root / 'test').rglob('test_*.py')):
        for i, line in enumerate(path.read_text().splitlines(), 1):
            if pattern.search(line):
                found.append(f'{path.relative_to(root)}:{i}: {line.strip()}')
    return found


def copy_tree(src: Path, dst: Path) -> None:
    shutil.copytree(
        src,
        dst,
        symlinks=True,
        ignore=shutil.ignore_patterns('.git', '.venv*', 'out', '.pytest_cache', '.hypothesis'),
    )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--sample', type=int, default=0, help='N constants drawn (0: all)')
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--only', nargs='*', default=[], help='MODULE.NAME or NAME')
    parser.add_argument('--list', action='store_true', help='print the population and exit')
    parser.add_argument('--full', action='store_true', help='run test/core and test/analysis')
    parser.add_argument('--tests', nargs='*', default=[], help='run these test files instead')
    parser.add_argument('--timeout', type=float, default=900.0, help='s per mutant run')
    parser.add_argument(
        '--no-baseline', action='store_true', help='skip the unmutated run (it warms the cache)'
    )
    args = parser.parse_args(argv)

    tuning, skipped = constants()
    if args.list:
        for c in tuning:
            print(f'{c.key:36s} {c.value!r}')
        print(f'\n{len(tuning)} tuning constants; {len(skipped)} structural:')
        for c, reason in skipped:
            print(f'  {c.key:34s} {reason}')
        return 0
    chosen = tuning
    if args.only:
        chosen = [c for c in tuning if c.key in args.only or c.name in args.only]
    elif args.sample:
        chosen = sorted(random.Random(args.seed).sample(tuning, args.sample), key=lambda c: c.key)
    for line in tautologies(ROOT, {c.name for c in chosen}):
        print(f'warning: a test asserts a constant, not a behaviour: {line}')
    which = (
        'test/core test/analysis' if args.full else ' '.join(args.tests) or 'per module (TESTS)'
    )
    print(
        f'{len(chosen)} of {len(tuning)} tuning constants (seed {args.seed}); tests: {which}',
        flush=True,
    )
    with tempfile.TemporaryDirectory(prefix='mutate-') as tmp:
        base = Path(tmp) / 'base'
        copy_tree(ROOT, base)
        if not args.no_baseline:  # the selection passes unmutated; the copy's cache is warm
            tests = ['test/core', 'test/analysis'] if args.full else list(args.tests)
            for stem in dict.fromkeys(Path(c.module).stem for c in chosen):
                tests += [] if args.full or args.tests else TESTS[stem]
            outcome, test = run_tests(base, list(dict.fromkeys(tests)), args.timeout)
            if outcome != 'pass':
                print(f'error: the unmutated tests do not pass ({outcome} {test})')
                return 2
        rows, pinned = [], 0
        print('| constant | value | 0.001x | caught by | 1000x | caught by |')
        print('|---|---|---|---|---|---|', flush=True)
        for c in chosen:
            stem = Path(c.module).stem
            tests = ['test/core', 'test/analysis'] if args.full else args.tests or TESTS[stem]
            cells = []
            for factor in (1e-3, 1e3):
                work = Path(tmp) / 'mutant'
                copy_tree(base, work)
                path = work / PACKAGE / c.module
                new = mutant_value(c.value, factor)
                path.write_text(mutate_source(path.read_text(), c.name, new))
                drop_numba_cache(work, compiled_importers(work, stem))
                t0 = time.monotonic()
                outcome, test = run_tests(work, tests, args.timeout)
                shutil.rmtree(work)
                cells.append((new, outcome, test, time.monotonic() - t0))
            both = all(o != 'pass' for _, o, _, _ in cells)
            pinned += both
            (lo, lo_o, lo_t, _), (hi, hi_o, hi_t, _) = cells
            row = (
                f'| {c.key} | {c.value!r} | {lo_o} ({lo!r}) | {lo_t.split("/")[-1]} '
                f'| {hi_o} ({hi!r}) | {hi_t.split("/")[-1]} |'
            )
            rows.append(row)
            print(row, flush=True)
        share = pinned / len(chosen) if chosen else 0.0
        print(f'\npinned both sides: {pinned} of {len(chosen)} ({100 * share:.0f} %)')
    return 0


if __name__ == '__main__':
    sys.exit(main())
