# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The compiled core's decorator: numba's ``njit(cache=True)``, compiled once per argument types.

numba types a constant argument (a literal, or a module constant such as a state offset) as
``Literal[int](value)`` and compiles a called function once per such literal: today's kernel
compiled its whole refinement chain twice (for ``iterations`` = ``Literal[int](0)`` and for int64),
the step twice (its row index), ``advance`` four times (its offsets). :func:`jit` compiles a
function called from compiled code for the plain types of its arguments only (a literal converts
to its type at the call; LLVM still folds the constant once it inlines the callee), so each
function is compiled once per real signature.

``inline='always'`` (numba's IR inlining: no compiled function of its own, typed in its caller) is
the right choice for a function called from one place: the caller's code is built and optimised
once instead of once per level of the call tree (numba links each callee's code into its caller
and optimises and emits the whole again).

:func:`borrowed` takes reference counting out of the per-sample loops: numba increments and
decrements the reference count of every array argument of every helper it inlines (numba #2345),
and its pruning pass leaves those of a helper with branches or early returns. Each is an atomic
operation behind an opaque call (LLVM then reloads the state from memory and spills its registers
around it): the kernel's ``run`` had 191 calls, most of them these, on its per-sample path, and its
batch rate went up 3.6x without them (docs/benchmarks.md, issue 24).
"""

from __future__ import annotations

import math
import sys
from types import FunctionType, ModuleType, SimpleNamespace

import numpy as np
from numba import config as numba_config
from numba import njit, typeof, types
from numba.core import cgutils
from numba.core.compiler_lock import global_compiler_lock
from numba.core.dispatcher import Dispatcher
from numba.extending import intrinsic


def _plain(ty):
    """The type without its literal value (``Literal[int](4)`` -> int64; tuples element-wise)."""
    if isinstance(ty, types.BaseTuple) and not isinstance(ty, types.BaseNamedTuple):
        return types.BaseTuple.from_types([_plain(t) for t in ty])
    return types.unliteral(ty)


def jit(fn=None, **options):
    """``njit(cache=True, **options)``, compiled from compiled callers for unliteral types."""
    if fn is None:
        return lambda f: jit(f, **options)
    dispatcher = njit(cache=True, **options)(fn)
    if options.get('inline', 'never') != 'never' or not isinstance(dispatcher, Dispatcher):
        return dispatcher  # (not a Dispatcher: numba's NUMBA_DISABLE_JIT=1, the plain function)
    template = dispatcher.get_call_template

    def get_call_template(args, kws):
        return template(tuple(_plain(a) for a in args), {k: _plain(v) for k, v in kws.items()})

    dispatcher.get_call_template = get_call_template
    return dispatcher


def entry(dispatcher, args):
    """The compiled code of ``dispatcher`` for the types of ``args`` (loaded from the cache or
    compiled, as a call would), to be called with arguments of those types only.

    A call through the dispatcher resolves the type of every argument first (numba's
    ``typeof`` per argument, then the overload lookup); the returned function skips that and only
    unboxes them. For a per-sample call with many array arguments that is a third of its cost.
    """
    if not isinstance(dispatcher, Dispatcher):
        return dispatcher  # NUMBA_DISABLE_JIT=1
    return dispatcher.compile(tuple(typeof(a) for a in args))


def python_of(fn):
    """The plain Python function of a compiled one (itself under ``NUMBA_DISABLE_JIT=1``)."""
    return getattr(fn, 'py_func', fn)


def available(dispatcher, args) -> bool:
    """Whether the compiled code of ``dispatcher`` for the types of ``args`` is in memory or in
    numba's cache (loaded then, as a call would): running it compiles nothing. Never compiles.

    A batch run whose code is neither runs uncompiled for a while
    (:func:`vib_estimator.core.estimator.run_batch`): a short record's answer in a second, not
    after a compile of 20 s.
    """
    if not isinstance(dispatcher, Dispatcher):
        return True  # NUMBA_DISABLE_JIT=1: plain Python, nothing to compile
    sig = tuple(typeof(a) for a in args)
    with global_compiler_lock:
        if dispatcher.overloads.get(sig) is not None:
            return True
        cres = dispatcher._cache.load_overload(sig, dispatcher.targetctx)
        if cres is None:
            return False
        # what Dispatcher.compile does with a cache hit (numba 0.59 to 0.68)
        dispatcher.targetctx.insert_user_function(cres.entry_point, cres.fndesc, [cres.library])
        dispatcher.add_overload(cres)
    return True


def _unreferenced(context, builder, signature, args):
    """:func:`borrowed`'s code: its array argument with a null meminfo and parent."""
    view = context.make_array(signature.args[0])(context, builder, value=args[0])
    view.meminfo = cgutils.get_null_value(view.meminfo.type)
    view.parent = cgutils.get_null_value(view.parent.type)
    return view._getvalue()


@intrinsic
def borrowed(typingctx, array):
    """``array`` without its reference count (a null meminfo): numba's increments and decrements
    of it, and of every view of it, become a test of a null pointer (:func:`_unreferenced`).

    For the compiled loops' own arguments only (:func:`core.kernel.run`, :func:`core.modes._run`):
    the caller holds the arrays for the whole call, and no view of them outlives it.
    """
    return array(array), _unreferenced


def _identity(array):
    """:func:`borrowed` outside compiled code: the array itself."""
    return array


if numba_config.DISABLE_JIT:  # numba's NUMBA_DISABLE_JIT=1: the kernels run as Python
    borrowed = _identity  # noqa: F811


#: ``math`` as compiled code has it: numba's ``math.hypot`` is the C library's (``np.hypot``),
#: Python's its own (they differ in the last bit)
_MATH = SimpleNamespace(**{k: getattr(math, k) for k in dir(math) if not k.startswith('_')})
_MATH.hypot = lambda x, y: float(np.hypot(x, y))

_interpreted: dict = {}


def interpreted(module) -> SimpleNamespace:
    """``module`` with its compiled functions as the plain Python they are written in: each
    :func:`jit` function (and each function defined in the module, such as the Python bodies of
    its overloads) runs uncompiled, calling the others uncompiled; a compiled function of another
    module it calls (``U.refine``) is that module's :func:`interpreted` one; :func:`borrowed` is
    the array itself. Built once per module (no compile, a few milliseconds).

    The same arithmetic in the same order, IEEE doubles both ways (no ``fastmath``): the results
    are the compiled code's floats (``test/core/test_interpreted.py``), about 100x slower. A
    start whose kernels are not compiled yet estimates with it while they compile
    (:mod:`vib_estimator.nodes.stream`); it calls nothing that would compile.
    """
    name = module.__name__
    if name in _interpreted:
        return _interpreted[name]
    space: dict = dict(vars(module))
    result = _interpreted[name] = SimpleNamespace()
    for key, value in vars(module).items():
        fn = python_of(value)
        if isinstance(fn, FunctionType) and fn.__module__ == name:
            space[key] = FunctionType(
                fn.__code__, space, fn.__name__, fn.__defaults__, fn.__closure__
            )
        elif isinstance(value, Dispatcher):  # another module's compiled function
            space[key] = getattr(interpreted(sys.modules[fn.__module__]), fn.__name__)
        elif isinstance(value, ModuleType) and _compiled(value) and value is not module:
            space[key] = interpreted(value)
        elif value is borrowed:
            space[key] = _identity
        elif value is math:
            space[key] = _MATH
    result.__dict__.update(space)
    return result


def _compiled(module) -> bool:
    """Whether ``module`` defines compiled functions (its :func:`interpreted` form differs)."""
    return any(
        isinstance(v, Dispatcher) and v.py_func.__module__ == module.__name__
        for v in vars(module).values()
    )
