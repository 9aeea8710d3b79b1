"""What several commands share: one-line errors, option types with units, strip options.

Only the command line imports this module.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import sys

from ipmc_asym.base.settings import MIN_THICKNESS
from ipmc_asym.base.units import parse_diffusion, parse_length, parse_pressure, parse_voltage
from ipmc_asym.integral.api import check_min_thickness
from ipmc_asym.model.limits import bare_number_warning, material_warnings, range_warning
from ipmc_asym.model.params import Strip, material_from_spec

__all__ = ["UsageError", "Parser", "add_strip_options", "add_material_options", "print_citations", "material_comments",
           "scene_with_material",
           "material_from_args", "strip_from_args",
           "arg_type", "count_type", "join_negative_values", "fmt_num", "c_moy_label", "length_type", "pressure_type",
           "voltage_type", "tol_type", "first_run_notice", "diffusion_type", "sidecar_path", "add_size_option", "check_size_caps",
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


def warn(line):
    """One line of warning on stderr (the command goes on)."""
    sys.stderr.write(f"ipmc-asym: warning: {line}\n")


def _positive(name, parse, example, check=None):
    def conv(text):
        v = parse(name, text)
        if v <= 0:
            raise ValueError(f"{name} must be > 0 (e.g. {example}); got {text!r}")
        if check is not None:
            check(text, v)
        return v

    return arg_type(conv, name)


def _plausible_length(name):
    def check(text, v):
        if name == "thickness" and v < MIN_THICKNESS:
            return  # refused by strip_from_args, the one floor every command shares
        line = bare_number_warning(name, text, v, f"--{name}") or range_warning(name, v, f"--{name}")
        if line:
            warn(line)

    return check


def length_type(name):
    return _positive(name, parse_length, "200um, 2cm", _plausible_length(name) if name in ("length", "width",
                                                                                           "thickness") else None)


def pressure_type(name):
    return _positive(name, parse_pressure, "130MPa")


def _plausible_diffusion(text, v):
    line = range_warning("D", v, "--diffusion")
    if line:
        warn(line)


def diffusion_type(name="--diffusion"):
    return _positive(name, parse_diffusion, "1e-10m2/s", _plausible_diffusion)


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


def add_strip_options(p, *, voltage=True, mechanics=True):
    """The strip/material options shared by several commands (SI or with units); ``mechanics``:
    the command reports beam outputs (``--strain-limit``)."""
    p.add_argument("--length", type=length_type("length"), default=0.02, help="strip length L (default 2cm)")
    p.add_argument("--width", type=length_type("width"), default=5e-3, help="TOTAL width 2l (default 5mm)")
    p.add_argument("--thickness", type=length_type("thickness"), default=200e-6,
                   help="TOTAL thickness 2e (default 200um)")
    if voltage:
        p.add_argument("--voltage", type=voltage_type(), default=1.0,
                       help="voltage phi0 (default 1V; sign = direction)")
    p.add_argument("--modulus", type=pressure_type("modulus"), default=None,
                   help="Young's modulus E (default: the material set's, 1.3e8 Pa for nafion-li)")
    p.add_argument("--c-moy", default=None,
                   help="mean cation concentration C_moy: paper (3082), formula (~3162) or a value in mol/m^3 "
                        "(default: the material set's, paper for nafion-li)")
    add_material_options(p)
    if not mechanics:
        return
    p.add_argument("--strain-limit", type=arg_type(_strain_limit, "strain-limit"), default=None,
                   help="face strain e|kappa| up to which the small-strain beam model is assumed (a model assumption: "
                        "rows above it are kept and flagged), e.g. 0.02 or 2%%; default the material's (1%%, "
                        "settings.STRAIN_LIMIT)")


def add_material_options(p):
    """``--material NAME|FILE.toml`` and ``--cite`` (every command with a material)."""
    p.add_argument("--material", default="nafion-li", metavar="NAME|FILE.toml",
                   help="material set (ipmc-asym materials lists them) or a material file (default nafion-li)")
    p.add_argument("--cite", action="store_true", help="print the bibliography of the run (material set and its sources)")


def _strain_limit(text):
    t = str(text).strip()
    scale = 0.01 if t.endswith("%") else 1.0
    try:
        v = float(t.rstrip("%")) * scale
    except ValueError:
        v = float("nan")
    if not 0.0 < v < 1.0:
        raise ValueError(f"--strain-limit must be a strain in (0, 1), e.g. 0.01 or 1%; got {text!r}")
    return v


def material_from_args(args):
    """The material of the options, through the library's one parser (params.material_from_spec)."""
    spec = {"preset": getattr(args, "material", "nafion-li")}
    if getattr(args, "modulus", None) is not None:
        spec["E"] = args.modulus
    if getattr(args, "c_moy", None) is not None:
        spec["c_moy"] = args.c_moy
    if getattr(args, "strain_limit", None) is not None:
        spec["strain_limit"] = args.strain_limit
    material = material_from_spec(spec, labels=_MATERIAL_OPTIONS)
    for line in material_warnings(material):
        warn(line)
    if getattr(args, "cite", False):
        print_citations(material, json_mode=bool(getattr(args, "json", False)))
    return material


def scene_with_material(path, args):
    """A scene file as a dict whose ``[material]`` table is ``--material`` alone when given (the
    scene's own material keys were written for its material); the path itself without it."""
    if getattr(args, "material", None) is None:
        return path
    from ipmc_asym.studies.scene_schema import load_scene  # deferred: only --material on a scene file needs it

    scene = load_scene(path)
    scene["material"] = {"preset": args.material}
    return scene


def material_comments(material) -> list:
    """Header comment lines of a result file: the material set and its numbered sources."""
    return [f"material set: {material.name}"] + [f"source [{i}]: {c}" for i, c in enumerate(material.sources, 1)]


def print_citations(material, json_mode=False):
    """``--cite``: the bibliography of the run (to stderr when stdout carries JSON)."""
    from ipmc_asym.model.materials import bibliography  # deferred: reads the material set files; only --cite needs it

    (sys.stderr if json_mode else sys.stdout).write(bibliography(material) + "\n")


_MATERIAL_OPTIONS = {"preset": "--material", "E": "--modulus", "c_moy": "--c-moy", "strain_limit": "--strain-limit"}


def strip_from_args(args):
    """The strip of the options; a thickness below ``settings.MIN_THICKNESS`` is refused here, the
    one check every command with strip options shares (integral.api.check_min_thickness)."""
    check_min_thickness(args.thickness)
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


def sidecar_path(out: str) -> str:
    """The metadata file beside a CSV of time series: ``x.csv`` -> ``x.csv.json`` (tau, thickness,
    model, units): the CSV keeps one header row, which ``pandas.read_csv`` reads as is."""
    return out + ".json"


#: file in the Numba cache directory that ``ipmc-asym warmup`` writes once every kernel is compiled
WARM_MARKER = ".ipmc_asym-warm"


def first_run_notice(command: str | None = None):
    """Say on stderr, before the work, that Numba compiles the kernels a command needs the first
    time it runs after install, instead of hanging silently (one line).

    Quiet once ``ipmc-asym warmup`` has compiled everything, or once ``command`` (a command and the
    variant whose kernels differ, e.g. ``"step-pnp"``) has run with this cache.
    """
    from ipmc_asym.kernels.jit import CACHE_DIR  # deferred: loads Numba; only the first-compile notice needs it

    ran = os.path.join(CACHE_DIR, f".ipmc_asym-ran-{command}") if command else None
    if os.path.exists(os.path.join(CACHE_DIR, WARM_MARKER)) or (ran is not None and os.path.exists(ran)):
        return
    empty = not (os.path.isdir(CACHE_DIR) and any(f.endswith(".nbi") for _, _, fs in os.walk(CACHE_DIR) for f in fs))
    if ran is None and not empty:
        return
    sys.stderr.write("ipmc-asym: compiling the Numba kernels this command needs, once (~20 s; up to ~2 min for "
                     "the PNP solver on a busy machine); later runs load them from the cache ('ipmc-asym warmup' "
                     "compiles all of them at once)\n")
    sys.stderr.flush()
    if ran is not None:
        _touch(ran)


def _touch(path):
    with contextlib.suppress(OSError):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "a", encoding="utf-8"):
            pass
