"""JSON output for every ``--json`` option: strict JSON, never a bare ``NaN``.

Non-finite floats (a fit with too few points, a quantity outside a formula's range) become
``null``; the producer says why in a neighbouring field (``note``, ``warnings``).  It lives in
``base/`` because every layer hands its results to it last: the writer sits below them all.
"""

from __future__ import annotations

import json
import math

import numpy as np

__all__ = ["clean", "dumps"]


def clean(obj):
    """Recursively convert numpy scalars/arrays to Python and non-finite floats to None."""
    if isinstance(obj, dict):
        return {str(k): clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return clean(obj.tolist())
    if isinstance(obj, (np.bool_,)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else None
    return obj


def dumps(obj, indent=2) -> str:
    return json.dumps(clean(obj), indent=indent, allow_nan=False)
