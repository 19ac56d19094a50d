# SPDX-License-Identifier: Apache-2.0
"""Checking and converting array arguments before their pointers go to C:
the right shape, a dtype that converts without loss of meaning, then
C-contiguous and aligned copies (np.require) that the caller keeps alive
for the duration of the call."""
import numbers
import os

import numpy as np

_REAL = "fiu"  # float, signed and unsigned integer dtypes


def _asarray(value, name, what):
    try:
        return np.asarray(value)
    except (ValueError, TypeError) as e:
        raise ValueError("%s must be %s; it cannot be read as an array (%s)"
                         % (name, what, e)) from None


def points(value, name, allow_empty=False, what="an (N, 3) array of real numbers"):
    """(N, 3) real numbers (floats, ints, lists of them) as float64."""
    a = _asarray(value, name, what)
    if a.dtype.kind not in _REAL:
        raise TypeError("%s must be %s, not an array of dtype %s" % (name, what, a.dtype))
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError("%s must be %s, not of shape %s" % (name, what, a.shape))
    if a.shape[0] == 0 and not allow_empty:
        raise ValueError("%s is empty: it must be %s with N >= 1" % (name, what))
    return np.require(a, np.float64, ["C_CONTIGUOUS", "ALIGNED"])


def triangles(value, name="triangles"):
    """(M, 3) integer indices (any integer dtype) as uint32. Negative
    indices and those beyond 32 bits are refused here, before the cast
    would wrap them; an index past the vertices is the library's to
    report."""
    what = "an (M, 3) array of integer vertex indices"
    a = _asarray(value, name, what)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError("%s must be %s, not of shape %s" % (name, what, a.shape))
    if a.size == 0:
        return np.zeros((0, 3), np.uint32)
    if a.dtype.kind not in "iu":
        raise TypeError("%s must be %s, not an array of dtype %s" % (name, what, a.dtype))
    lo, hi = int(a.min()), int(a.max())
    if lo < 0:
        row = int(np.argwhere(a < 0)[0][0])
        raise ValueError("%s: row %d holds the negative index %d" % (name, row, lo))
    if hi >= 1 << 32:
        raise ValueError("%s: index %d does not fit in 32 bits" % (name, hi))
    return np.require(a, np.uint32, ["C_CONTIGUOUS", "ALIGNED"])


def vec3(value, name):
    """Three finite real numbers as a tuple of floats."""
    a = _asarray(value, name, "three numbers")
    if a.dtype.kind not in _REAL or a.shape != (3,):
        raise TypeError("%s must be three real numbers (x, y, z), not %r" % (name, value))
    out = tuple(float(x) for x in a)
    if not all(np.isfinite(out)):
        raise ValueError("%s must be finite, not %r" % (name, out))
    return out


def number(value, name, positive=False, allow_zero=True):
    """A finite real number (not a bool) as a float."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError("%s must be a number, not %r" % (name, value))
    v = float(value)
    if not np.isfinite(v):
        raise ValueError("%s must be finite, not %r" % (name, value))
    if positive and not (v > 0 or (allow_zero and v == 0)):
        raise ValueError("%s must be %s, not %r" % (name, "> 0" if not allow_zero else ">= 0",
                                                   value))
    return v


def whole(value, name, lo=None, hi=None):
    """A whole number (not a bool) in lo..hi."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError("%s must be a whole number, not %r" % (name, value))
    v = int(value)
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise ValueError("%s must be a whole number in %s..%s, not %d"
                         % (name, lo if lo is not None else "", hi if hi is not None else "", v))
    return v


def path(value, name="path"):
    """A file name (str, bytes or os.PathLike) as bytes for C."""
    try:
        p = os.fspath(value)
    except TypeError:
        raise TypeError("%s must be a file name (str or os.PathLike), not %r"
                        % (name, value)) from None
    b = os.fsencode(p)
    if not b:
        raise ValueError("%s is empty" % name)
    if b"\0" in b:
        raise ValueError("%s holds a NUL character" % name)
    return b


def choice(value, name, options):
    """One of the names in `options` (a dict name -> value)."""
    if not isinstance(value, str) or value not in options:
        names = ", ".join(k for k in options if k != "centre")
        raise ValueError("unknown %s %r (%s)" % (name, value, names))
    return options[value]


def text(value, name, limit=None):
    if not isinstance(value, str):
        raise TypeError("%s must be a str, not %r" % (name, value))
    b = value.encode("utf-8")
    if b"\0" in b:
        raise ValueError("%s holds a NUL character" % name)
    if limit is not None and len(b) >= limit:
        raise ValueError("%s must be shorter than %d bytes" % (name, limit))
    return b


def ptr(a):
    """The data pointer of an array checked above (as a c_void_p value)."""
    return a.ctypes.data if a.size else None
