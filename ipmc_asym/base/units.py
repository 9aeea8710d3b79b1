"""Parse user-facing quantities with units (``200um``, ``2 cm``, ``1V``, ``130MPa``) to SI.

A bare number is SI.  Errors are one-line ``ValueError`` naming the parameter.
"""

from __future__ import annotations

import math
import re
from decimal import Decimal

import numpy as np

__all__ = ["parse_length", "parse_voltage", "parse_pressure", "parse_force", "parse_time", "parse_diffusion", "parse_resistance",
           "parse_sheet_resistance", "parse_quantity", "fmt_length", "SWEEP_VARIABLES",
           "parse_vary_spec", "parse_vary", "vary_values"]

_LENGTH = {
    "m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6,
    "micron": 1e-6, "microns": 1e-6, "nm": 1e-9,
}
_VOLT = {"v": 1.0, "mv": 1e-3, "kv": 1e3, "uv": 1e-6, "µv": 1e-6}
_PRESSURE = {"pa": 1.0, "kpa": 1e3, "mpa": 1e6, "gpa": 1e9}
_FORCE = {"N": 1.0, "mN": 1e-3, "uN": 1e-6, "µN": 1e-6, "μN": 1e-6, "kN": 1e3}
_TIME = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "μs": 1e-6, "min": 60.0, "h": 3600.0}
_DIFFUSION = {"m2/s": 1.0, "m^2/s": 1.0, "cm2/s": 1e-4, "cm^2/s": 1e-4, "mm2/s": 1e-6, "mm^2/s": 1e-6,
              "um2/s": 1e-12, "µm2/s": 1e-12, "um^2/s": 1e-12, "µm^2/s": 1e-12}
# sheet (surface) resistance of a film, Ohm per square (matched case-insensitively: "ohm/sq", "Ohm/sq")
_SHEET = {"ohm/sq": 1.0, "ohm/square": 1.0, "ohm/□": 1.0, "ω/sq": 1.0, "ω/□": 1.0, "kohm/sq": 1e3}

# a resistance, Ohm (case-sensitive: MOhm is mega, mOhm milli)
_RESISTANCE = {"Ohm": 1.0, "ohm": 1.0, "Ω": 1.0, "kOhm": 1e3, "kohm": 1e3, "kΩ": 1e3, "MOhm": 1e6, "Mohm": 1e6,
               "MΩ": 1e6, "mOhm": 1e-3, "mohm": 1e-3, "mΩ": 1e-3}
_NUM = re.compile(r"^\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*([^\s\d].*?)?\s*$")


def _scaled(number: str, factor: float) -> float:
    """``number * factor`` rounded once: a power-of-ten unit shifts the decimal exponent exactly
    (``"200um"`` is the double nearest 2e-4, as ``"200e-6"`` is; the product of the doubles 200 and
    1e-6 is one ulp below it); any other factor (min, h) multiplies."""
    k = round(math.log10(factor))
    if float(f"1e{k}") == factor:
        return float(Decimal(number).scaleb(k))
    return float(number) * factor


def parse_quantity(name: str, text, units: dict, unit_name: str, case_sensitive: bool = True) -> float:
    """Parse ``text`` (number or number+unit from ``units``) into SI; ``ValueError`` naming ``name``."""
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        v = float(text)
    else:
        s = str(text)
        m = _NUM.match(s)
        if not m:
            # a finite number and a unit, shown with the first units it takes (1V, 1mV, ...)
            raise ValueError(
                f"{name}: cannot read {text!r} as a {unit_name}: a finite number with one of the units "
                f"{', '.join(list(units)[:4])}, ... (e.g. 1{next(iter(units))}), or a bare number in SI"
            )
        v = float(m.group(1))
        u = m.group(2)
        if u:
            key = u if case_sensitive else u.lower()
            if key not in units:
                raise ValueError(
                    f"{name}: unknown unit {u!r} for a {unit_name}; allowed: {', '.join(units)}"
                )
            v = _scaled(m.group(1), units[key])
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


def parse_force(name: str, text) -> float:
    """``'1.2mN'``, ``'5uN'``, ``'0.001'`` -> newtons."""
    return parse_quantity(name, text, _FORCE, "force")


def parse_time(name: str, text) -> float:
    """``'20ms'``, ``'0.5s'``, ``'2min'``, ``'0.1'`` -> seconds."""
    return parse_quantity(name, text, _TIME, "time")


def parse_diffusion(name: str, text) -> float:
    """``'1e-10m2/s'``, ``'1e-6 cm2/s'``, ``'1e-10'`` -> m^2/s."""
    return parse_quantity(name, text, _DIFFUSION, "diffusion coefficient")


def parse_sheet_resistance(name: str, text) -> float:
    """``'2.5ohm/sq'``, ``'2.5 Ω/sq'``, ``'2.5'`` -> Ohm per square."""
    return parse_quantity(name, text, _SHEET, "sheet resistance", case_sensitive=False)


def parse_resistance(name: str, text) -> float:
    """``'10kOhm'``, ``'2.2 MΩ'``, ``'470ohm'``, ``'1e4'`` -> ohms (the unit's case matters: M, m)."""
    return parse_quantity(name, text, _RESISTANCE, "resistance")


def fmt_length(x: float) -> str:
    """Human-readable length (``200 µm``, ``2 cm``)."""
    ax = abs(x)
    for unit, f in (("m", 1.0), ("cm", 1e-2), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9)):
        if ax >= f or unit == "nm":
            return f"{x / f:.4g} {unit}"
    return f"{x:g} m"


#: the quantities a sweep can vary (SI; width and thickness TOTAL 2l, 2e)
SWEEP_VARIABLES = ("length", "width", "thickness", "voltage", "modulus")


def _parse_value(name, text):
    if name in ("length", "width", "thickness"):
        return parse_length(name, text)
    if name == "voltage":
        return parse_voltage(name, text)
    return parse_pressure(name, text)


#: most values of one sweep axis (800 MB of float64)
MAX_AXIS_POINTS = 10**8


def parse_vary_spec(spec: str):
    """``'length=1cm:4cm:16'`` -> ``(name, start, stop, n, log)`` without building the values
    (so that a huge ``n`` can be refused before any memory is used)."""
    if "=" not in spec:
        raise ValueError(f"--vary must be NAME=START:STOP:N[:log]; got {spec!r}")
    name, rng = spec.split("=", 1)
    name = name.strip()
    if name not in SWEEP_VARIABLES:
        raise ValueError(f"--vary name must be one of {', '.join(SWEEP_VARIABLES)}; got {name!r}")
    parts = rng.split(":")
    log = False
    if len(parts) == 4 and parts[3].strip().lower() in ("log", "lin"):
        log = parts[3].strip().lower() == "log"
        parts = parts[:3]
    if len(parts) != 3:
        raise ValueError(f"--vary {name}: expected START:STOP:N[:log]; got {rng!r}")
    a = _parse_value(name, parts[0])
    b = _parse_value(name, parts[1])
    try:
        nf = float(parts[2].strip().replace("_", ""))
    except ValueError:
        raise ValueError(f"--vary {name}: N must be an integer >= 1 (e.g. 16 or 1e6); got {parts[2]!r}") from None
    if not math.isfinite(nf) or not nf.is_integer() or nf < 1:
        raise ValueError(f"--vary {name}: N must be an integer >= 1 (e.g. 16 or 1e6); got {parts[2]!r}")
    if nf > MAX_AXIS_POINTS:  # each axis' values are held in memory (8 bytes each), whatever --max-rows says
        raise ValueError(f"--vary {name}: N must be at most {MAX_AXIS_POINTS:g} (an axis' values are held in memory); "
                         f"got {parts[2]!r}")
    if log and (a <= 0 or b <= 0):
        raise ValueError(f"--vary {name}: log spacing needs START, STOP > 0")
    if name != "voltage" and (a <= 0 or b <= 0):
        raise ValueError(f"--vary {name}: values must be > 0")
    return name, a, b, int(nf), log


def vary_values(a, b, n, log):
    return np.geomspace(a, b, n) if log else np.linspace(a, b, n)


def parse_vary(spec: str):
    """``'length=1cm:4cm:16'`` -> ``("length", array)``; ``':log'`` suffix for log spacing."""
    name, a, b, n, log = parse_vary_spec(spec)
    return name, vary_values(a, b, n, log)
