"""Compile-time specialisation of the numba kernels on feature flags.

The hot kernels take their feature flags (kernel type, viscosity type, density
diffusion type, shifting mode) as ``numba.literally`` arguments, so each
combination is a separate compiled function in which the unused branches are
removed by the compiler: an unused feature costs nothing.

Calling such a dispatcher from Python goes through numba's literal-dispatch
path every time (milliseconds).  :func:`specialised` calls it once (compiling
or loading from the cache) and returns the compiled entry point of the
specialisation, which is then called directly (~0.1 µs per call).  The entry
point does not check argument types: callers must pass the dtypes and array
layouts used at specialisation time.
"""
from . import _env  # noqa: F401  (sets OMP_WAIT_POLICY before numba import)
from numba.core import types


def _matches(sig, literal_args):
    for k, v in literal_args.items():
        t = sig[k]
        if not isinstance(t, types.Literal) or t.literal_value != v:
            return False
    return True


def specialised(dispatcher, args, literal_positions):
    """Return the compiled entry point of ``dispatcher`` for ``args``.

    ``literal_positions`` lists the argument positions that are literal flags.
    The dispatcher is called once with ``args`` to compile (or load) the
    specialisation, which is then looked up among its overloads.
    """
    # compile on copies: the kernels write into their array arguments, and this
    # call must not advance the real state (it would, e.g., on a resumed run)
    dispatcher(*[a.copy() if hasattr(a, "copy") and hasattr(a, "shape") else a for a in args])
    want = {k: args[k] for k in literal_positions}
    found = [cres for sig, cres in dispatcher.overloads.items()
             if _matches(sig, want)]
    if not found:
        raise RuntimeError("no specialisation of %s for %r" % (dispatcher, want))
    # Several signatures may share the flags (e.g. float vs int scalars);
    # take the one typed from exactly these arguments.
    sig = dispatcher.typeof_pyval
    argtys = tuple(types.literal(args[k]) if k in want else sig(a)
                   for k, a in enumerate(args))
    cres = dispatcher.overloads.get(argtys, found[-1])
    return cres.entry_point
