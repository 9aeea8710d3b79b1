"""Parse user-facing quantities with units (``200um``, ``2 cm``, ``1V``, ``130MPa``) to SI.

A bare number is SI.  Errors are one-line ``ValueError`` naming the parameter.
"""

from __future__ import annotations

import math
import re

__all__ = ["parse_length", "parse_voltage", "parse_pressure", "parse_quantity", "fmt_length"]

_LENGTH = {
    "m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6,
    "micron": 1e-6, "microns": 1e-6, "nm": 1e-9,
}
_VOLT = {"v": 1.0, "mv": 1e-3, "kv": 1e3, "uv": 1e-6, "µv": 1e-6}
_PRESSURE = {"pa": 1.0, "kpa": 1e3, "mpa": 1e6, "gpa": 1e9}

_NUM = re.compile(r"^\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*([^\s\d].*?)?\s*$")


def parse_quantity(name: str, text, units: dict, unit_name: str, case_sensitive: bool = True) -> float:
    """Parse ``text`` (number or number+unit from ``units``) into SI; ``ValueError`` naming ``name``."""
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        v = float(text)
    else:
        s = str(text)
        m = _NUM.match(s)
        if not m:
            raise ValueError(
                f"{name}: cannot read {text!r} as a {unit_name} (examples: "
                f"{', '.join(list(units)[:4])}; a bare number is SI)"
            )
        v = float(m.group(1))
        u = m.group(2)
        if u:
            key = u if case_sensitive else u.lower()
            if key not in units:
                raise ValueError(
                    f"{name}: unknown unit {u!r} for a {unit_name}; allowed: {', '.join(units)}"
                )
            v *= units[key]
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite; got {text!r}")
    return v


def parse_length(name: str, text) -> float:
    """``'200um'``, ``'200µm'``, ``'0.2mm'``, ``'2 cm'``, ``'0.02'`` -> metres."""
    return parse_quantity(name, text, _LENGTH, "length")


def parse_voltage(name: str, text) -> float:
    """``'1V'``, ``'500mV'``, ``'-2'`` -> volts."""
    return parse_quantity(name, text, _VOLT, "voltage", case_sensitive=False)


def parse_pressure(name: str, text) -> float:
    """``'130MPa'``, ``'1.3e8'`` -> pascals."""
    return parse_quantity(name, text, _PRESSURE, "pressure", case_sensitive=False)


def fmt_length(x: float) -> str:
    """Human-readable length (``200 µm``, ``2 cm``)."""
    ax = abs(x)
    for unit, f in (("m", 1.0), ("cm", 1e-2), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9)):
        if ax >= f or unit == "nm":
            return f"{x / f:.4g} {unit}"
    return f"{x:g} m"
