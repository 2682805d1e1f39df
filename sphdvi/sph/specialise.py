"""Compile-time specialisation of the numba kernels on feature flags.

The hot kernels take their feature flags (kernel type, viscosity type, density
diffusion type, shifting mode) as ``numba.literally`` arguments, so each
combination is a separate compiled function in which the unused branches are
removed by the compiler: an unused feature costs nothing.

Calling such a dispatcher from Python goes through numba's literal-dispatch
path every time (milliseconds).  :func:`specialised` compiles (or loads from
the cache) the specialisation for an explicit signature, without running the
kernel, and returns its compiled entry point, which is then called directly
(~0.1 µs per call).  The entry point does not check argument types: callers
must pass the dtypes and array layouts used at specialisation time.
"""
from . import _env  # noqa: F401
from numba import typeof
from numba.core import types


def signature_of(args, literal_positions):
    """numba argument types of ``args``, literal at ``literal_positions``."""
    return tuple(types.literal(a) if k in literal_positions else typeof(a)
                 for k, a in enumerate(args))


def specialised(dispatcher, args, literal_positions):
    """Compile ``dispatcher`` for the types of ``args`` and return its entry point.

    ``literal_positions`` lists the argument positions that are literal flags.
    Nothing is executed: the arrays in ``args`` only give their types.
    """
    sig = signature_of(args, set(literal_positions))
    dispatcher.compile(sig)
    return dispatcher.overloads[sig].entry_point
