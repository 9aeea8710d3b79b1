"""What several commands share: one-line errors, option types with units, strip options.

Only the command line imports this module.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import sys

from ipmc_asym.base.units import parse_diffusion, parse_length, parse_pressure, parse_voltage
from ipmc_asym.model.params import Strip, material_from_spec

__all__ = ["UsageError", "Parser", "add_strip_options", "material_from_args", "strip_from_args",
           "arg_type", "count_type", "join_negative_values", "fmt_num", "c_moy_label", "length_type", "pressure_type",
           "voltage_type", "tol_type", "first_run_notice", "diffusion_type", "add_size_option", "check_size_caps",
           "seed_type", "model_help"]


class UsageError(Exception):
    """Bad input at the command line (exit status 2)."""


class Parser(argparse.ArgumentParser):
    """argparse with a one-line error and exit status 2."""

    def error(self, message):
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        raise SystemExit(2)


def arg_type(conv, name="value"):
    """Wrap a converter raising ``ValueError`` into an argparse type (one-line message)."""

    def f(text):
        try:
            return conv(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    f.__name__ = name
    return f


def _positive(name, parse, example):
    def conv(text):
        v = parse(name, text)
        if v <= 0:
            raise ValueError(f"{name} must be > 0 (e.g. {example}); got {text!r}")
        return v

    return arg_type(conv, name)


def length_type(name):
    return _positive(name, parse_length, "200um, 2cm")


def pressure_type(name):
    return _positive(name, parse_pressure, "130MPa")


def diffusion_type(name="--diffusion"):
    return _positive(name, parse_diffusion, "1e-10m2/s")


def voltage_type(name="voltage"):
    return arg_type(lambda t: parse_voltage(name, t), name)


def _tol(text):
    """``0.01``, ``1%``, ``1e-3`` -> a relative tolerance in (0, 1)."""
    t = str(text).strip()
    scale = 1.0
    if t.endswith("%"):
        t, scale = t[:-1].strip(), 0.01
    try:
        v = float(t) * scale
    except ValueError:
        raise ValueError(f"--tol must be a relative tolerance in (0, 1), e.g. 0.01 or 1%; got {text!r}") from None
    if not 0.0 < v < 1.0:
        raise ValueError(f"--tol must be a relative tolerance in (0, 1), e.g. 0.01 or 1%; got {text!r}")
    return v


tol_type = arg_type(_tol, "tol")


def count_type(name, minimum=1):
    """An integer >= ``minimum``, also written ``1e6`` or ``10**6``-style ``1_000_000``."""

    def conv(text):
        try:
            v = float(str(text).replace("_", ""))
        except ValueError:
            raise ValueError(f"{name} must be an integer >= {minimum} (e.g. 1000000 or 1e6); got {text!r}") from None
        if not v.is_integer() or v < minimum:
            raise ValueError(f"{name} must be an integer >= {minimum} (e.g. 1000000 or 1e6); got {text!r}")
        return int(v)

    return arg_type(conv, name)


def add_size_option(p, flag, *, default, maximum, minimum=1, help="", cap_flag=None, metavar=None):
    """A size-like option ``flag`` with its documented cap ``--max-<name>`` (settable, like sweep's ``--max-rows``).

    The cap is checked by :func:`check_size_caps` before any work (``main`` calls it), so a
    size that would exhaust memory or time is refused in one line, exit 2.
    """
    cap_flag = cap_flag or "--max-" + flag.lstrip("-")
    kw = {"metavar": metavar} if metavar else {}
    p.add_argument(flag, type=count_type(flag, minimum), default=default,
                   help=f"{help} (default {default:g}; at most {cap_flag}, default {maximum:g})".replace("%", "%%"), **kw)
    p.add_argument(cap_flag, type=count_type(cap_flag), default=maximum,
                   help=f"refuse {flag} above this (default {maximum:g}: memory and time stay bounded)")
    caps = p.get_default("_size_caps") or ()
    p.set_defaults(_size_caps=tuple(caps) + ((flag, cap_flag),))


def _dest(flag):
    return flag.lstrip("-").replace("-", "_")


def check_size_caps(args):
    """Refuse (ValueError, one line) every size option of ``args`` above its cap."""
    for flag, cap in getattr(args, "_size_caps", ()) or ():
        v, m = getattr(args, _dest(flag), None), getattr(args, _dest(cap), None)
        if v is not None and m is not None and v > m:
            raise ValueError(f"{flag} {v:.6g} is above {cap} {m:.6g} (the cap bounding memory and time); "
                             f"lower {flag} or raise {cap}")


def _seed(text):
    t = str(text).strip().replace("_", "")
    try:
        v = int(t)
    except ValueError:
        try:
            f = float(t)
            v = int(f) if f.is_integer() else None
        except (ValueError, OverflowError):
            v = None
    if v is None or not 0 <= v < 2**63:
        raise ValueError(f"--seed must be an integer in [0, 2^63), e.g. 0 or 42; got {text!r}")
    return v


#: ``--seed``: a non-negative integer (checked at parsing, before any work)
seed_type = arg_type(_seed, "seed")


def model_help(default, *, all_allowed=False):
    """Help text of ``--model`` stating its default (the default differs by command)."""
    choices = "constant, linear, affine" + (" or all" if all_allowed else "")
    return f"permittivity model: {choices} (default {default})"


_NEGATIVE = re.compile(r"^-(\d|\.\d)")


def join_negative_values(argv):
    """``['--voltage', '-1V']`` -> ``['--voltage=-1V']`` for every long option.

    argparse reads a token starting with ``-`` as an option unless it is a bare negative
    number (``-1``), so ``--voltage -1V`` and ``--vary voltage=...`` style values with a unit
    would be rejected; a long option followed by ``-<digit>`` or ``-.<digit>`` always takes
    it as its value (no option of ipmc-asym starts with a digit).
    """
    out = []
    i = 0
    argv = list(argv)
    while i < len(argv):
        a = argv[i]
        if (a.startswith("--") and "=" not in a and a != "--" and i + 1 < len(argv)
                and _NEGATIVE.match(argv[i + 1])):
            out.append(f"{a}={argv[i + 1]}")
            i += 2
            continue
        out.append(a)
        i += 1
    return out


def fmt_num(x, spec="g"):
    """``format(x, spec)`` with a zero never signed (``-0``, ``-0.000`` of a tiny negative) and
    ``None`` as ``n/a``."""
    if x is None:
        return "n/a"
    x = float(x)
    if x == 0.0:
        x = 0.0  # drops the sign of -0.0
    text = format(x, spec)
    mant = text.split("e")[0].split("E")[0]
    if "-" in mant and not any(c in "123456789" for c in mant):
        # rounds to zero: no sign (the spec's width kept)
        width = re.match(r"[<>=^]?[-+ ]?#?0?(\d*)", spec).group(1)
        text = text.replace("-", "", 1).rjust(int(width) if width else 0)
    return text


def c_moy_label(material) -> str:
    """``3082 mol/m^3 (paper)`` / ``(formula)`` / ``(given)``."""
    src = material.c_moy
    how = src if isinstance(src, str) else "given"
    return f"{material.C_moy:.6g} mol/m^3 ({how})"


def add_strip_options(p, *, voltage=True):
    """The strip/material options shared by several commands (SI or with units)."""
    p.add_argument("--length", type=length_type("length"), default=0.02, help="strip length L (default 2cm)")
    p.add_argument("--width", type=length_type("width"), default=5e-3, help="TOTAL width 2l (default 5mm)")
    p.add_argument("--thickness", type=length_type("thickness"), default=200e-6,
                   help="TOTAL thickness 2e (default 200um)")
    if voltage:
        p.add_argument("--voltage", type=voltage_type(), default=1.0,
                       help="voltage phi0 (default 1V; sign = direction)")
    p.add_argument("--modulus", type=pressure_type("modulus"), default=1.3e8,
                   help="Young's modulus E (default 1.3e8 Pa)")
    p.add_argument("--c-moy", default="paper",
                   help="mean cation concentration C_moy: paper (3082, default), formula (~3162) or a value in mol/m^3")


def material_from_args(args):
    """The material of the options, through the library's one parser (params.material_from_spec)."""
    spec = {"preset": getattr(args, "material", "nafion-li"), "E": args.modulus, "c_moy": args.c_moy}
    return material_from_spec(spec, labels=_MATERIAL_OPTIONS)


_MATERIAL_OPTIONS = {"preset": "--material", "E": "--modulus", "c_moy": "--c-moy"}


def strip_from_args(args):
    return Strip(length=args.length, width=args.width, thickness=args.thickness,
                 voltage=getattr(args, "voltage", 1.0))


@contextlib.contextmanager
def new_dir_removed_on_failure(path):
    """Around work writing into directory ``path``: if the work fails (or Ctrl-C) and the
    directory did not exist before and is still empty, remove it (no empty directory left)."""
    existed = os.path.isdir(path)
    try:
        yield
    except BaseException:
        if not existed and os.path.isdir(path) and not os.listdir(path):
            with contextlib.suppress(OSError):
                os.rmdir(path)
        raise


def first_run_notice():
    """Numba compiles on the first run after install: say so instead of hanging silently."""
    from ipmc_asym.kernels.jit import CACHE_DIR  # deferred: loads Numba; only the first-compile notice needs it

    if not (os.path.isdir(CACHE_DIR) and any(f.endswith(".nbi") for _, _, fs in os.walk(CACHE_DIR) for f in fs)):
        sys.stderr.write("ipmc-asym: compiling the Numba kernels (first run after install, ~10-30 s)...\n")
        sys.stderr.flush()
