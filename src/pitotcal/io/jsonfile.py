"""JSON files pitotcal writes (result, truth, study summaries): one sanitiser, one writer."""

import json
import math
from pathlib import Path

import numpy as np

from .atomic import atomic_open

__all__ = ["json_ready", "read_json", "write_json"]


def json_ready(value):
    """Plain Python types for `json.dump`: numpy scalars and arrays become numbers and lists,
    tuples lists, dict keys strings, and NaN / infinities None (JSON null)."""
    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_ready(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_ready(value.tolist())
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, Path):
        return str(value)
    return value


def write_json(path, obj):
    """Write `obj` (after `json_ready`) as indented, strictly valid JSON, whole or not at all
    (`pitotcal.io.atomic`); returns the path."""
    with atomic_open(path, "w") as f:
        json.dump(json_ready(obj), f, indent=2, allow_nan=False)
        f.write("\n")
    return path


def read_json(path, name=None):
    """The content of the JSON file `path`; a one-line PitotcalError naming `name` (default the
    path) when it cannot be read or is not JSON."""
    from pitotcal.core.errors import PitotcalError

    label = str(path) if name is None else name
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except json.JSONDecodeError as exc:
        raise PitotcalError(f"{label}: not JSON ({exc.msg}, line {exc.lineno}); not a JSON "
                            "file pitotcal wrote") from None
    except UnicodeDecodeError:
        raise PitotcalError(f"{label}: not JSON (binary content); not a JSON file pitotcal "
                            "wrote") from None
    except RecursionError:
        raise PitotcalError(f"{label}: JSON nested too deeply to read; not a JSON file "
                            "pitotcal wrote") from None
    except OSError as exc:
        raise PitotcalError(f"{label}: cannot read it ({exc.strerror})") from None
