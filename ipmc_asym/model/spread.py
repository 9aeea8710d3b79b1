"""The model-form spread: the range of one output over equally plausible model forms
(``estimate``, ``charge``, ``uq``), plain numbers in, a dict out.

It sits with the models, below the layers that evaluate them: each report calls it last, on
its way out, after its numerical work.
"""

from __future__ import annotations

__all__ = ["spread_of"]


def spread_of(values: dict, numerical_error=None) -> dict:
    """``{"min", "max", "ratio", "values", "numerical_error"}`` of ``values`` (label -> number or
    None); ``ratio`` = max|y|/min|y| (None when the sign changes or a value is 0)."""
    got = [v for v in values.values() if v is not None]
    lo, hi = (min(got), max(got)) if got else (None, None)
    ratio = None
    if got and (lo > 0 or hi < 0):
        a = [abs(v) for v in got]
        ratio = max(a) / min(a)
    return {"min": lo, "max": hi, "ratio": ratio, "values": dict(values), "numerical_error": numerical_error}
