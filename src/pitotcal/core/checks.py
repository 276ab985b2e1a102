"""The validators of user-facing numbers: one set for the whole package.

Each returns the value as a plain Python number or raises a `PitotcalError` that names the
parameter (`param`), so the command line can show the flag instead (`--cas-min-kt`).
"""

import dataclasses
import math

import numpy as np

from .errors import PitotcalError

__all__ = ["choice", "exact", "integer", "number", "option_dict", "positive", "recovery_bounds",
           "round_to_limit", "wrap_deg"]


def number(name, value, lo=-math.inf, hi=math.inf, *, lo_open=False, hi_open=False):
    """`value` as a finite float inside [lo, hi] (open ends with `lo_open` / `hi_open`)."""
    if isinstance(value, (bool, np.bool_)):
        raise PitotcalError(f"{name} must be a number, got {value!r}", param=name)
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise PitotcalError(f"{name} must be a number, got {value!r}", param=name) from None
    if not math.isfinite(x):
        raise PitotcalError(f"{name} {x:g} must be a finite number", param=name)
    below = x < lo or (lo_open and x == lo)
    above = x > hi or (hi_open and x == hi)
    if below or above:
        rules = []
        if math.isfinite(lo):
            rules.append(f"{'>' if lo_open else '>='} {exact(lo)}")
        if math.isfinite(hi):
            rules.append(f"{'<' if hi_open else '<='} {exact(hi)}")
        raise PitotcalError(f"{name} {exact(x)} must be {' and '.join(rules)}", param=name)
    return x


def exact(x):
    """`x` as short text that still tells it from its neighbours: ``{:g}`` when that reads
    back as `x`, else up to 12 significant digits (a limit of 333333.33 is never shown as the
    333333 it refuses)."""
    text = f"{x:g}"
    return text if float(text) == x else f"{x:.12g}"


def round_to_limit(x, lo=True, digits=3):
    """`x` rounded to `digits` significant digits away from the forbidden side: up for a
    lower limit (`lo`), down for an upper one, so a suggested value always passes."""
    if x == 0 or not math.isfinite(x):
        return x
    step = 10.0 ** (math.floor(math.log10(abs(x))) - digits + 1)
    k = (math.ceil if lo else math.floor)(x / step)
    while True:             # the text of the value, read back, is on the allowed side
        value = float(f"{k * step:.{digits + 1}g}")
        if (value >= x) if lo else (value <= x):
            return value
        k += 1 if lo else -1


def positive(name, value):
    """`value` as a finite float > 0."""
    return number(name, value, 0.0, lo_open=True)


def integer(name, value, lo=None, hi=None):
    """`value` as an int inside [lo, hi]; a float with a fractional part is refused."""
    x = number(name, value, -math.inf if lo is None else lo, math.inf if hi is None else hi)
    if x != int(x):
        raise PitotcalError(f"{name} {x:g} must be a whole number", param=name)
    return int(x)


def choice(name, value, choices):
    """`value` if it is one of `choices` (strings); the message lists them in order."""
    if not isinstance(value, str) or value not in choices:
        raise PitotcalError(f"{name} {value!r} is not one of {', '.join(choices)}", param=name)
    return value


def option_dict(name, value):
    """A copy of the options dict `value` ({} for None), e.g. IPOPT options passed through."""
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise PitotcalError(f"{name} must be a dict, not {type(value).__name__}", param=name)
    return dict(value)


def wrap_deg(angle_deg):
    """An angle difference wrapped into [-180, 180) degrees (arrays too)."""
    return (np.asarray(angle_deg, dtype=float) + 180.0) % 360.0 - 180.0


def with_overrides(cls, obj, overrides, *, name, caller):
    """`obj` (a frozen `cls` dataclass, or None for its defaults) with the fields in the dict
    `overrides` put in (they win); an unknown field is a TypeError naming `caller`, an `obj` of
    another type a PitotcalError naming the argument `name`."""
    unknown = sorted(set(overrides) - {f.name for f in dataclasses.fields(cls)})
    if unknown:
        raise TypeError(f"{caller}() got an unexpected keyword argument {unknown[0]!r}")
    if obj is None:
        return cls(**overrides)
    if not isinstance(obj, cls):
        raise PitotcalError(f"{name} must be a {cls.__name__} or None, got "
                            f"{type(obj).__name__}", param=name)
    return dataclasses.replace(obj, **overrides) if overrides else obj


def recovery_bounds(bounds, name="recovery_bounds"):
    """(low, high) of a temperature probe's recovery factor, checked: 0 < low <= high <= 1.5
    (above 1, which no probe has, only to reproduce a peer that allows it)."""
    try:
        lo, hi = (float(b) for b in bounds)
    except (TypeError, ValueError):
        raise PitotcalError(f"`{name}` {bounds!r} must be two numbers (low, high)",
                            param=name) from None
    if not 0.0 < lo <= hi <= 1.5:
        raise PitotcalError(f"`{name}` {bounds!r} must satisfy 0 < low <= high <= 1.5",
                            param=name)
    return lo, hi
