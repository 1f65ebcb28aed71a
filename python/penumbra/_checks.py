"""Argument checks: every value a caller passes is turned into what the native module takes, or
refused with a ``TypeError`` (wrong kind) or ``ValueError`` (wrong value) naming the argument."""

from __future__ import annotations

import math
import numbers
from typing import Any, Optional, Sequence

import numpy as np


def rows3(value: Any, name: str, *, allow_single: bool = False) -> np.ndarray:
    """An (N, 3) C-contiguous float64 array of finite numbers; with ``allow_single``, a lone
    row of three is taken as (1, 3)."""
    try:
        array = np.asarray(value)
    except Exception as e:  # ragged lists, objects numpy cannot hold
        raise TypeError(f"{name} must be an (N, 3) array of numbers: {e}") from None
    if array.dtype.kind not in "iuf":
        raise TypeError(f"{name} must hold real numbers, not {array.dtype}")
    array = array.astype(np.float64, copy=False)
    if allow_single and array.shape == (3,):
        array = array.reshape(1, 3)
    if array.ndim != 2 or array.shape[1] != 3:
        raise ValueError(f"{name} must have shape (N, 3), not {array.shape}")
    finite = np.isfinite(array).all(axis=1)
    if not finite.all():
        row = int(np.argmin(finite))
        raise ValueError(f"{name}: row {row} is not finite: {array[row].tolist()}")
    return np.ascontiguousarray(array)


# The largest whole number the native side takes (64 bits, unsigned).
MAX_COUNT = 2**64 - 1


def normals(value: Any, name: str, points: int) -> np.ndarray:
    """One normal per point, (points, 3): given so, or one (3,) normal for all."""
    rows = rows3(value, name, allow_single=True)
    if len(rows) == 1 and points != 1:
        rows = np.repeat(rows, points, axis=0)
    if len(rows) != points:
        raise ValueError(f"{name} has {len(rows)} rows for {points} points")
    return rows


def count(value: Any, name: str, *, minimum: int = 1, maximum: int = MAX_COUNT) -> Optional[int]:
    """A whole number from ``minimum`` to ``maximum``, or None."""
    if value is None:
        return None
    return whole(value, name, minimum=minimum, maximum=maximum)


def whole(value: Any, name: str, *, minimum: int = 1, maximum: int = MAX_COUNT) -> int:
    """A whole number from ``minimum`` to ``maximum``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be a whole number, not {type(value).__name__}")
    result = int(value)
    if result < minimum:
        raise ValueError(f"{name} must be at least {minimum}, not {result}")
    if result > maximum:
        raise ValueError(f"{name} must be at most {maximum}, not {result}")
    return result


def number(value: Any, name: str, *, positive: bool = False) -> Optional[float]:
    """A finite real number (positive, if asked), or None."""
    if value is None:
        return None
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a number, not {type(value).__name__}")
    result = float(value)
    if not math.isfinite(result):
        raise ValueError(f"{name} must be finite, not {result}")
    if positive and result <= 0:
        raise ValueError(f"{name} must be positive, not {result}")
    return result


def flag(value: Any, name: str) -> bool:
    """True or False."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, not {type(value).__name__}")
    return bool(value)


def choice(value: Any, name: str, choices: Sequence[str]) -> Optional[str]:
    """One of ``choices``, or None."""
    if value is None:
        return None
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a string, not {type(value).__name__}")
    if value not in choices:
        listed = ", ".join(repr(c) for c in choices)
        raise ValueError(f"{name} must be one of {listed}, not {value!r}")
    return value


def surface_ids(value: Any, name: str, points: int, surfaces: int) -> Optional[list[int]]:
    """One surface id per point, from 0 to ``surfaces - 1`` (-1: none), or None."""
    if value is None:
        return None
    array = np.asarray(value)
    if array.dtype.kind not in "iu":
        raise TypeError(f"{name} must hold whole numbers, not {array.dtype}")
    if array.shape != (points,):
        raise ValueError(f"{name} must have shape ({points},), one id per point, not {array.shape}")
    ids = [int(i) for i in array]
    wrong = [i for i in ids if not -1 <= i < surfaces]
    if wrong:
        raise ValueError(f"{name}: {wrong[0]} is no surface id; ids run from 0 to {surfaces - 1} (-1: none)")
    return ids
