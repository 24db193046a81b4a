# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The optional extras: packages the package works without, each imported through :func:`optional`.

pyarrow, Dask's distributed, tqdm, threadpoolctl and pyOMA-2 have no rosdep key (README, "On a
Jazzy machine"): a Jazzy machine may lack them, or have a pip-installed one that refuses to load
(pyarrow 26 raises ``ImportError: pyarrow requires NumPy 2.0 or newer`` beside Ubuntu 24.04's numpy
1.26; a wheel built for another ABI can raise anything). Either way the package goes on without it:
:func:`optional` returns the module, or None after one line on stderr naming the package, why it is
unavailable and what is done instead (:data:`FALLBACKS`, the documented fallback), once per package
and process.
"""

from __future__ import annotations

import functools
import importlib
import sys
from types import ModuleType
from typing import Optional, Set

#: each optional package (by import name) and what the package does without it
FALLBACKS = {
    'pyarrow': 'CSV files are read by the exact rules (slower); survey --out FILE.parquet writes '
    'FILE.csv instead',
    'distributed': 'survey --scheduler runs on a local process pool instead',
    'tqdm': 'survey shows no progress bar',
    'threadpoolctl': "BLAS calls are not held to one thread (the matrix pencil's SVDs are slower "
    'on a busy machine)',
    'pyoma2': "the benchmarks leave out pyOMA2's SSI-cov peer",
}

#: how the warning line of an unavailable extra begins
WARNING = 'vib_estimator: warning: optional package'
#: the packages already reported unavailable in this process
_reported: Set[str] = set()


@functools.lru_cache(maxsize=None)
def optional(name: str) -> Optional[ModuleType]:
    """The module ``name`` (a package of :data:`FALLBACKS` or one of its submodules, e.g.
    ``pyarrow.csv``), or None when it cannot be imported for any reason: missing, or failing as it
    loads. The first failure of a package writes one warning line to stderr."""
    package = name.partition('.')[0]
    if package not in FALLBACKS:
        raise ValueError(f'{package!r} is not an optional extra ({", ".join(FALLBACKS)})')
    try:
        return importlib.import_module(name)
    except Exception as err:  # noqa: BLE001 -- whatever breaks an extra's import, go on without it
        if package not in _reported:
            _reported.add(package)
            why = (str(err).strip().splitlines() or [''])[0]
            sys.stderr.write(
                f'{WARNING} {package} unavailable '
                f'({type(err).__name__}: {why}): {FALLBACKS[package]}\n'
            )
        return None


def forget() -> None:
    """Forget what :func:`optional` found (tests that install or break an extra)."""
    optional.cache_clear()
    _reported.clear()
