"""Python callables in a run's loop: each wrapped so that what reaches the loop is
three real, finite numbers or a CallbackError naming the callable and the sample."""
from __future__ import annotations

import math
import numbers
from typing import Any, Callable, Optional

from ._native import RunError, ScenarioError


class CallbackError(RunError):
    """A Python callable in a run's loop raised or gave a value the run cannot take
    (not three real, finite numbers); the message names the callable and the sample,
    the callable's own exception is the cause. The run stopped after that sample and
    its report (marked interrupted) was written."""


Operator = Callable[[int, float, "numpy.ndarray"], Any]
Predictor = Callable[[int, int, "numpy.ndarray"], Any]



def _refused(r: Any, what: str, n: int, why: str) -> CallbackError:
    shown = " ".join(repr(r).split())  # an array's repr on one line
    return CallbackError(f"{what} at sample {n}: gave {shown}, not three real numbers ({why})")


def _kind(r: Any, a: Any, what: str, n: int) -> None:
    """Refuses an array that holds anything but real numbers, saying what it holds."""
    kind = a.dtype.kind
    if kind in "fiu":
        return
    if kind == "O" and all(isinstance(x, numbers.Real) and not isinstance(x, bool)
                           for x in a.reshape(-1)):
        return
    why = {"b": "booleans", "c": "complex numbers", "U": "text", "S": "bytes"}.get(
        kind, f"values of NumPy kind {kind!r}")
    raise _refused(r, what, n, why)


# The quick way's array: NumPy's ndarray of float64 (a builtin dtype is one object).
# Set once NumPy is imported; until then nothing is one.
_NDARRAY: Any = None
_F64: Any = object()


def _numpy() -> Any:
    """NumPy, imported when a run first takes a callable (not at `import tactile`)."""
    global _NDARRAY, _F64
    import numpy as np
    _NDARRAY, _F64 = np.ndarray, np.dtype(np.float64)
    return np


def _three(r: Any, what: str, n: int) -> tuple:
    """A callable's result as three finite floats, or CallbackError naming the sample.
    A tuple or list of three Python floats or ints, or a float64 (3,) array, takes the
    quick way (a few hundred nanoseconds a call); anything else is read by NumPy and
    must hold real numbers only: text, complex numbers, booleans and masked arrays
    (whose mask the loop would drop) are refused."""
    if type(r) is tuple or type(r) is list:
        # A float (NumPy's float64 is one) or exactly an int: a bool is an int to
        # Python, but no position.
        if len(r) == 3:
            x, y, z = r
            if ((isinstance(x, float) or type(x) is int)
                    and (isinstance(y, float) or type(y) is int)
                    and (isinstance(z, float) or type(z) is int)):
                x, y, z = float(x), float(y), float(z)
                if math.isfinite(x) and math.isfinite(y) and math.isfinite(z):
                    return x, y, z
    elif type(r) is _NDARRAY and r.dtype is _F64 and r.shape == (3,):
        x, y, z = r.tolist()
        if math.isfinite(x) and math.isfinite(y) and math.isfinite(z):
            return x, y, z
    np = _numpy()
    if isinstance(r, np.ma.MaskedArray):
        raise _refused(r, what, n, "a masked array: its mask would be dropped")
    if isinstance(r, (str, bytes)):
        raise _refused(r, what, n, "text")
    try:
        a = np.asarray(r)
    except (TypeError, ValueError) as e:
        raise CallbackError(f"{what} at sample {n}: gave {r!r}, not three numbers ({e})") from None
    if a.shape != (3,):
        raise CallbackError(f"{what} at sample {n}: gave an array of shape {a.shape}, "
                            "not three numbers (shape (3,))")
    _kind(r, a, what, n)
    a = a.astype(np.float64)
    if not np.isfinite(a).all():
        raise CallbackError(f"{what} at sample {n}: gave {a.tolist()}, not finite")
    return float(a[0]), float(a[1]), float(a[2])


def _raised(what: str, n: int, e: Exception) -> CallbackError:
    return CallbackError(f"{what} at sample {n}: {type(e).__name__}: {e}")


def _operator(f: Operator) -> Callable:
    """The operator as the loop calls it: (n, t, fx, fy, fz) -> three floats."""
    np = _numpy()

    def call(n: int, t: float, fx: float, fy: float, fz: float) -> tuple:
        try:
            r = f(n, t, np.array((fx, fy, fz)))
        except Exception as e:
            raise _raised("operator", n, e) from e
        return _three(r, "operator", n)
    return call


def _predictor(f: Predictor, what: str) -> Callable:
    """A predictor as the loop calls it: (n, to, history's bytes) -> three floats;
    the history a read-only (k, 4) array, rows [sample, x, y, z], oldest first."""
    np = _numpy()

    def call(n: int, to: int, raw: bytes) -> tuple:
        history = np.frombuffer(raw, dtype=np.float64).reshape(-1, 4)
        try:
            r = f(n, to, history)
        except Exception as e:
            raise _raised(what, n, e) from e
        return _three(r, what, n)
    return call


def hook(f: Any, wrap: Callable, name: str, *args: str) -> Optional[Callable]:
    """`f` wrapped for the loop, None for None; a ScenarioError for what is not a
    function."""
    if f is None:
        return None
    if not callable(f):
        raise ScenarioError(f"{name}: give a function, not a {type(f).__name__}")
    return wrap(f, *args)


def hooks(operator: Optional[Operator], backward_predictor: Optional[Predictor],
          forward_predictor: Optional[Predictor]) -> tuple:
    """The three callables of a run, wrapped for its loop (None where not given)."""
    return (hook(operator, _operator, "operator"),
            hook(backward_predictor, _predictor, "backward_predictor", "backward predictor"),
            hook(forward_predictor, _predictor, "forward_predictor", "forward predictor"))
