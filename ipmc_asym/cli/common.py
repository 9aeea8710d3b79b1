"""What several commands share: one-line errors, option types with units, strip options.

Only the command line imports this module.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import math
import os
import re
import sys

import numpy as np

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.settings import FREQUENCY_RANGE, MAX_SHEET_RESISTANCE, MIN_THICKNESS
from ipmc_asym.base.units import (
    fmt_length,
    parse_diffusion,
    parse_length,
    parse_pressure,
    parse_quantity,
    parse_resistance,
    parse_sheet_resistance,
    parse_time,
    parse_voltage,
)
from ipmc_asym.io.fileio import atomic_write, check_output_path, output_format
from ipmc_asym.model.electrode import METALS
from ipmc_asym.model.limits import material_warnings, range_warning, value_warning
from ipmc_asym.model.materials import bibliography, material_comments
from ipmc_asym.model.params import Strip, check_diffusion, check_min_thickness, material_from_spec, set_thickness

__all__ = ["UsageError", "Parser", "add_strip_options", "add_material_options", "print_citations", "material_comments",
           "scene_with_material",
           "material_from_args", "strip_from_args", "strip_and_material",
           "arg_type", "count_type", "join_negative_values", "fmt_num", "c_moy_label", "length_type", "pressure_type",
           "voltage_type", "tol_type", "time_tol_type",
           "first_run_notice", "spread_count", "diffusion_type", "sidecar_path", "DOCUMENT_FORMATS", "add_document_out",
           "given", "RecordGiven",
           "write_document", "column_rows", "strip_rows", "add_size_option", "check_size_caps", "cap_type",
           "add_output_option", "check_outputs",
           "seed_type", "model_help", "viscous_modulus_type", "duration_type", "waveform_type", "sheet_resistance_type",
           "frequency_type", "add_beam_options", "SOLVER_ALIASES", "add_solver_option", "add_line_options",
           "add_support_options", "support_from_args", "CLAMPED_UNITS", "print_clamped"]


class UsageError(Exception):
    """Bad input at the command line (exit status 2)."""


class Parser(argparse.ArgumentParser):
    """argparse with a one-line error and exit status 2."""

    def error(self, message):
        sys.stderr.write(f"{self.prog}: error: {_named_once(message)}\n")
        raise SystemExit(2)


def _named_once(message):
    """argparse's ``argument --NAME: MSG`` where MSG, from a converter that names its parameter
    for the library's callers too, begins with ``--NAME: `` or ``NAME: ``: the name said once."""
    head, sep, rest = message.partition(": ")
    if not (sep and head.startswith("argument ")):
        return message
    for name in head[len("argument "):].split("/"):
        bare = name.lstrip("-")
        for lead in (f"--{bare}: ", f"{bare}: "):
            if bare and rest.startswith(lead):
                return f"{head}: {rest[len(lead):]}"
    return message


def arg_type(conv, name="value"):
    """Wrap a converter raising ``ValueError`` into an argparse type (one-line message)."""

    def f(text):
        try:
            return conv(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    f.__name__ = name
    return f


def spread_count(d: dict) -> str:
    """What a model-form spread line adds where some variants have no value (withheld, or not
    computed): over how many it was taken; empty where every variant has one."""
    vals = list(d["values"].values())
    k = sum(v is not None for v in vals)
    return "" if k == len(vals) else f"   (over {k} of {len(vals)} variants; the others n/a)"


def warn(line):
    """One line of warning on stderr (the command goes on)."""
    sys.stderr.write(f"ipmc-asym: warning: {line}\n")


def nu_type(text):
    """``--nu``: the drained Poisson ratio of the sensing mode, in [0, 0.5] (sense, freq --mode sensing)."""
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not 0.0 <= v <= 0.5:
        raise ValueError(f"--nu must be a drained Poisson ratio in [0, 0.5]; got {text!r}")
    return v


def load_type(text):
    """``--load`` of the sensing mode (sense, freq --mode sensing, fit on sensing data): ``short``,
    ``open`` or a resistance > 0 across the electrodes (``10kOhm``, ``470ohm``; a bare number is ohms)."""
    t = str(text).strip().lower()
    if t in ("short", "open"):
        return t
    try:
        R = parse_resistance("--load", text)
    except ValueError as exc:  # the unit parser's reason (e.g. an unknown unit) kept after the rule
        reason = str(exc).removeprefix("--load: ")
        raise ValueError(f"--load must be short, open or a resistance > 0 Ohm (e.g. 10kOhm); got {text!r}: "
                         f"{reason}") from None
    if not R > 0.0:
        raise ValueError(f"--load must be short, open or a resistance > 0 Ohm (e.g. 10kOhm); got {text!r}")
    return R


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
            return  # refused by the Strip (its thickness floor), the one check every command shares
        line = value_warning(name, text, v, f"--{name}")
        if line:
            warn(line)

    return check


def length_type(name):
    return _positive(name, parse_length, "200um, 2cm", _plausible_length(name) if name in ("length", "width",
                                                                                           "thickness") else None)


def pressure_type(name):
    return _positive(name, parse_pressure, "130MPa")


def _plausible_diffusion(text, v):
    check_diffusion(v, "--diffusion")  # the refusal before the plausibility warning: one line
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


def _time_tol(text):
    """``tol_type``, or ``auto`` (kept as the string: the library resolves it) or ``none`` (None)."""
    t = str(text).strip().lower()
    if t == "none":
        return None
    if t == "auto":
        return "auto"
    try:
        return _tol(text)
    except ValueError:
        raise ValueError(f"--tol must be auto, none or a relative tolerance in (0, 1), e.g. 0.01 or 1%; "
                         f"got {text!r}") from None


#: ``--tol`` of the time responses (step, drive): a tolerance, ``auto`` (the errors stated where they can
#: be, :func:`ipmc_asym.dynamics.entry.stated_tol`) or ``none`` (the bare circuit)
time_tol_type = arg_type(_time_tol, "tol")


def count_type(name, minimum=1, maximum=None, why=""):
    """An integer >= ``minimum`` (and <= ``maximum``, where given, for the reason ``why``), also
    written ``1e6`` or ``10**6``-style ``1_000_000``."""
    if maximum is None:
        allowed = f"an integer >= {minimum} (e.g. 1000000 or 1e6)"
    else:
        allowed = f"an integer from {minimum} to {maximum:g}" + (f" ({why})" if why else "")

    def conv(text):
        try:
            v = float(str(text).replace("_", ""))
        except ValueError:
            raise ValueError(f"{name} must be {allowed}; got {text!r}") from None
        if not v.is_integer() or v < minimum or (maximum is not None and v > maximum):
            raise ValueError(f"{name} must be {allowed}; got {text!r}")
        return int(v)

    return arg_type(conv, name)


def cap_type(flag, ceiling):
    """The type of a settable cap ``--max-<name>``: an integer from 1 to its hard ``ceiling``
    (a ``settings.MAX_*_CEILING``)."""
    return count_type(flag, 1, ceiling, "the ceiling of this cap: memory and time stay bounded")


def add_size_option(p, flag, *, default, maximum, ceiling, minimum=1, help="", cap_flag=None, metavar=None):
    """A size-like option ``flag`` with its documented cap ``--max-<name>`` (settable, like sweep's ``--max-rows``,
    up to its hard ``ceiling``, a ``settings.MAX_*_CEILING``).

    The cap is checked by :func:`check_size_caps` before any work (``main`` calls it), so a
    size that would exhaust memory or time is refused in one line, exit 2.
    """
    cap_flag = cap_flag or "--max-" + flag.lstrip("-")
    kw = {"metavar": metavar} if metavar else {}
    p.add_argument(flag, type=count_type(flag, minimum), default=default,
                   help=f"{help} (default {default:g}; at most {cap_flag}, default {maximum:g})".replace("%", "%%"), **kw)
    p.add_argument(cap_flag, type=cap_type(cap_flag, ceiling), default=maximum,
                   help=f"refuse {flag} above this (default {maximum:g}, at most {ceiling:g}: memory and time stay "
                        "bounded)")
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


def add_output_option(p, flag="--out", *, formats=None, kind="file", sidecar=False, **kw):
    """An output option ``flag`` (a file whose format follows its extension, one of ``formats``, or
    a directory, ``kind="dir"``), checked by :func:`check_outputs` before any work.

    ``main`` calls :func:`check_outputs` right after parsing: a format the command cannot write
    (``--out d.xlsx`` of a CSV writer, ``--plot x.xlsx``), an empty path (``--out ''``), a
    missing or read-only directory is refused in one line before anything is computed, the same
    way for every command (``io.fileio.check_output_path``).  ``sidecar``: the file's metadata
    sidecar (:func:`sidecar_path`) is checked with it.
    """
    p.add_argument(flag, **kw)
    outs = p.get_default("_outputs") or ()
    p.set_defaults(_outputs=tuple(outs) + ((flag, kind, tuple(formats) if formats else None),))
    if sidecar:
        p.set_defaults(_sidecars=tuple(p.get_default("_sidecars") or ()) + (flag,))


# ---- --out of a one-document command (estimate, charge, freq) ----------------------------------------

#: formats of a one-document ``--out``
DOCUMENT_FORMATS = (".json", ".csv")


def add_document_out(p, rows: str):
    """``--out F.json|F.csv`` on the parser ``p``; ``rows`` says what one CSV row is."""
    add_output_option(p, "--out", formats=DOCUMENT_FORMATS, sidecar=True, default=None, metavar="F.json|F.csv",
                      help=f"also write the result to a file (atomically): .json the --json document; .csv one row "
                           f"per {rows} (SI units, the header the column names), the rest of the document in "
                           "F.csv.json")


def write_document(path, doc: dict, rows: list, meta: dict) -> None:
    """Write ``doc`` (the ``--json`` document) to ``path`` (.json), or ``rows`` (dicts: one CSV row
    each, nested checks flattened to ``check_<name>``, lists joined by ``"; "``) with ``meta`` in
    the sidecar ``path.json`` (.csv)."""
    if output_format(path, DOCUMENT_FORMATS) == ".json":
        with atomic_write(path) as fh:
            fh.write(dumps(doc, indent=2) + "\n")
        return
    flat = [_flat(r) for r in rows]
    cols = list(dict.fromkeys(k for r in flat for k in r))
    with atomic_write(path) as fh:
        wr = csv.writer(fh)
        wr.writerow(cols)
        for r in flat:
            wr.writerow([_cell(r.get(k)) for k in cols])
    with atomic_write(sidecar_path(path)) as fh:
        fh.write(dumps(meta, indent=2) + "\n")


#: the strip's inputs repeated in each CSV row of a one-document --out (which thickness: the names say)
STRIP_COLUMNS = ("thickness_total", "half_thickness_e", "voltage", "length", "width_total")


def strip_rows(inputs: dict, rows: list) -> list:
    """``rows`` (dicts) each led by the strip's :data:`STRIP_COLUMNS` from a document's ``inputs``."""
    echo = {k: inputs[k] for k in STRIP_COLUMNS}
    return [dict(echo, **r) for r in rows]


def column_rows(cols: dict) -> list:
    """Rows (dicts of Python numbers) of the equal-length columns ``cols`` (arrays)."""
    arrs = {k: np.asarray(v).reshape(-1) for k, v in cols.items()}
    n = min((a.size for a in arrs.values()), default=0)
    return [{k: a[i].item() for k, a in arrs.items()} for i in range(n)]


def _flat(row: dict) -> dict:
    out = {}
    for k, v in row.items():
        if isinstance(v, dict):
            out.update({f"check_{c}" if k == "checks" else f"{k}_{c}": x for c, x in v.items()})
        else:
            out[k] = v
    return out


def _cell(v) -> str:
    # a number as the shortest text that reads back to the same double; None (withheld) empty
    if v is None:
        return ""
    if isinstance(v, bool):
        return str(v)
    if isinstance(v, float):
        return repr(float(v))  # a NumPy scalar's repr names its type
    if isinstance(v, (list, tuple)):
        return "; ".join(str(x) for x in v)
    return str(v)


def check_outputs(args):
    """Check every output option of ``args`` given (even empty) with :func:`io.fileio.check_output_path`."""
    for flag, kind, formats in getattr(args, "_outputs", ()) or ():
        v = getattr(args, _dest(flag), None)
        if v is not None:
            check_output_path(v, kind, flag, formats=formats)
    for flag in getattr(args, "_sidecars", ()) or ():
        v = getattr(args, _dest(flag), None)
        if v:
            check_output_path(sidecar_path(v), "file")


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


class RecordGiven(argparse.Action):
    """Store the value and record that the option was given (``given(args, dest)``): where its
    default and a value typed equal to it differ in meaning (``step --waveform`` with ``--voltage``)."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)
        setattr(namespace, "_given", tuple(getattr(namespace, "_given", ()) or ()) + (self.dest,))


def given(args, dest: str) -> bool:
    """Whether the option whose destination is ``dest`` was given on the command line (options
    stored by :class:`RecordGiven`)."""
    return dest in (getattr(args, "_given", ()) or ())


def add_strip_options(p, *, voltage=True, mechanics=True):
    """The strip/material options shared by several commands (SI or with units); ``mechanics``:
    the command reports beam outputs (``--strain-limit``)."""
    p.add_argument("--length", type=length_type("length"), default=0.02, action=RecordGiven,
                   help="strip length L (default 2cm)")
    p.add_argument("--width", type=length_type("width"), default=5e-3, action=RecordGiven, help="TOTAL width 2l (default 5mm)")
    p.add_argument("--thickness", type=length_type("thickness"), default=None, action=RecordGiven,
                   help="TOTAL membrane thickness 2e (default: the material set's typical thickness, e.g. 183um for "
                        "nafion-117-h, said in the output; 200um for nafion-li)")
    if voltage:
        p.add_argument("--voltage", type=voltage_type(), default=1.0, action=RecordGiven,
                       help="voltage phi0 (default 1V; sign = direction)")
    p.add_argument("--modulus", type=pressure_type("modulus"), default=None,
                   help="Young's modulus E (default: the material set's, 1.3e8 Pa for nafion-li)")
    p.add_argument("--c-moy", default=None,
                   help="mean cation concentration C_moy: paper (3082), formula (~3162) or a value in mol/m^3 "
                        "(default: the material set's, paper for nafion-li)")
    add_electrode_options(p)
    add_material_options(p)
    if not mechanics:
        return
    p.add_argument("--strain-limit", type=arg_type(_strain_limit, "strain-limit"), default=None,
                   help="face strain e|kappa| up to which the small-strain beam model is assumed (a model assumption: "
                        "rows above it are kept and flagged), e.g. 0.02 or 2%%; default the material's (1%%, "
                        "settings.STRAIN_LIMIT)")


def _electrode_thickness(text):
    v = parse_length("--electrode-thickness", text)
    if not (math.isfinite(v) and v >= 0.0):
        raise ValueError(f"--electrode-thickness must be a length >= 0 (each layer), e.g. 5um or 0; got {text!r}")
    return v


def _electrode_density(text):
    v = parse_quantity("--electrode-density", text, {"kg/m^3": 1.0, "kg/m3": 1.0, "g/cm^3": 1e3, "g/cm3": 1e3},
                       "density")
    if not (math.isfinite(v) and v >= 0.0):
        raise ValueError(f"--electrode-density must be a density >= 0, e.g. 21450kg/m3 or 21.45g/cm3; got {text!r}")
    return v


def add_electrode_options(p):
    """The metal electrode layers of the beam (``model.electrode``; default: the material set's,
    none for the paper's bare membrane)."""
    p.add_argument("--electrode-thickness", type=arg_type(_electrode_thickness, "electrode-thickness"), default=None,
                   help="thickness t_m of EACH metal electrode layer on the faces (composite beam: stiffness, mass; "
                        "the electrochemistry keeps the membrane thickness), e.g. 5um; default the material set's "
                        "(none: the paper's bare membrane); 0 = no layer")
    p.add_argument("--electrode-metal", default=None, choices=sorted(METALS),
                   help="metal of the layers: its handbook modulus and density with their source (ipmc_asym/model/"
                        "electrode.py METALS)")
    p.add_argument("--electrode-modulus", type=pressure_type("electrode-modulus"), default=None,
                   help="Young's modulus E_m of the layers (overrides the metal's), e.g. 171GPa")
    p.add_argument("--electrode-density", type=arg_type(_electrode_density, "electrode-density"), default=None,
                   help="density of the layers (overrides the metal's; dynamics only), e.g. 21450kg/m3")


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
    spec = _material_spec(args)
    material = material_from_spec(spec, labels=_MATERIAL_OPTIONS)
    for line in material_warnings(material):
        warn(line)
    if getattr(args, "cite", False):
        print_citations(material, json_mode=bool(getattr(args, "json", False)))
    return material


def _material_spec(args) -> dict:
    """The material options given, as a ``[material]`` table of :func:`params.material_from_spec`."""
    spec = {"preset": getattr(args, "material", "nafion-li")}
    for key, dest in (("E", "modulus"), ("c_moy", "c_moy"), ("strain_limit", "strain_limit"),
                      ("electrode_thickness", "electrode_thickness"), ("electrode_metal", "electrode_metal"),
                      ("electrode_modulus", "electrode_modulus"), ("electrode_density", "electrode_density")):
        if getattr(args, dest, None) is not None:
            spec[key] = getattr(args, dest)
    return spec


def strip_and_material(args):
    """``(strip, material, thickness_note)`` of the strip and material options, built in one place.

    The constructors check what they are given (the Strip its geometry and the thickness floor,
    the material parser every key), so the layers below trust both.  The material set's typical
    thickness stands in for a ``--thickness`` not given (``thickness_note`` says so; empty when
    the option was given or the set states none).  Warnings on implausible material values go to
    stderr and ``--cite`` prints the bibliography here, before any work, as every command did.
    """
    spec = _material_spec(args)
    strip = strip_from_args(args)
    material = material_from_spec(spec, labels=_MATERIAL_OPTIONS)
    # said once both are built (a refused option has printed nothing), and written here rather
    # than through warn()/print_citations(): this helper reads options and calls the model only
    for line in material_warnings(material):
        sys.stderr.write(f"ipmc-asym: warning: {line}\n")
    if getattr(args, "cite", False):
        (sys.stderr if getattr(args, "json", False) else sys.stdout).write(bibliography(material) + "\n")
    if getattr(args, "diffusion", None) is not None:  # the dynamic commands' --diffusion over the set's D
        material = material.with_(D=args.diffusion)
    return strip, material, getattr(args, "thickness_note", "")


def scene_with_material(path, args):
    """A scene file as a dict whose ``[material]`` table is ``--material`` alone when given (the
    scene's own material keys were written for its material); the path itself without it."""
    layer = electrode_spec(args)
    if getattr(args, "material", None) is None and not layer:
        return path
    from ipmc_asym.studies.scene_schema import load_scene  # deferred: only --material on a scene file needs it

    scene = load_scene(path)
    if getattr(args, "material", None) is not None:
        scene["material"] = {"preset": args.material}
    if layer:  # the layer options on top of the scene's (or --material's) material table
        table = dict(scene.get("material") or {})
        for k in ("electrode_thickness", "electrode_metal", "electrode_modulus", "electrode_density"):
            table.pop(k, None)
        table.update(layer)
        scene["material"] = table
    return scene


def electrode_spec(args) -> dict:
    """The electrode options given (``electrode_thickness`` ... -> value), for a material table."""
    return {k: getattr(args, k) for k in ("electrode_thickness", "electrode_metal", "electrode_modulus",
                                          "electrode_density") if getattr(args, k, None) is not None}


def print_citations(material, json_mode=False):
    """``--cite``: the bibliography of the run (to stderr when stdout carries JSON)."""
    (sys.stderr if json_mode else sys.stdout).write(bibliography(material) + "\n")


_MATERIAL_OPTIONS = {"preset": "--material", "E": "--modulus", "c_moy": "--c-moy", "strain_limit": "--strain-limit",
                     "electrode_thickness": "--electrode-thickness", "electrode_metal": "--electrode-metal",
                     "electrode_modulus": "--electrode-modulus", "electrode_density": "--electrode-density"}


#: the strip's thickness when neither --thickness nor the material set gives one (m)
DEFAULT_THICKNESS = 200e-6


def default_thickness(material_name):
    """``(thickness m, note)``: the material set's typical thickness (:func:`params.set_thickness`),
    else :data:`DEFAULT_THICKNESS` with an empty note (the output stays as it was)."""
    try:
        got = set_thickness(material_name or "nafion-li")
    except ValueError:  # an unknown set: material_from_args says so, in its own words
        got = None
    return got if got is not None else (DEFAULT_THICKNESS, "")


def strip_from_args(args):
    """The strip of the options; a thickness below ``settings.MIN_THICKNESS`` is refused here, in
    the option's words, before the Strip's own check."""
    if getattr(args, "thickness", None) is None:
        args.thickness, args.thickness_note = default_thickness(getattr(args, "material", None))
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
    from ipmc_asym.kernels.jit import CACHE_DIR, compile_notice_given  # deferred: loads Numba

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
    compile_notice_given()
    if ran is not None:
        _touch(ran)


def _touch(path):
    with contextlib.suppress(OSError):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "a", encoding="utf-8"):
            pass


# ---- the dynamic commands' options (step, drive, freq, fit): one definition each -------------------------

_VISCOSITY = {"Pa s": 1.0, "Pa*s": 1.0, "Pa.s": 1.0, "kPa s": 1e3, "kPa*s": 1e3, "MPa s": 1e6, "MPa*s": 1e6}


def viscous_modulus_type(name="--viscous-modulus"):
    """The Kelvin-Voigt viscous modulus eta_E (Pa s, ``'2kPa s'``), >= 0."""
    def conv(text):
        v = parse_quantity(name, str(text).replace("·", " ").strip(), _VISCOSITY, "viscous modulus (Pa s)")
        if v < 0:
            raise ValueError(f"{name} must be >= 0 Pa s (e.g. 0, 1e4, '2kPa s'); got {text!r}")
        return v

    return arg_type(conv, name)


def _duration(text):
    from ipmc_asym.dynamics.waveforms import check_time_span  # deferred: start-up

    v = parse_time("--duration", text)
    if v <= 0:
        raise ValueError(f"--duration must be > 0 (e.g. 0.5s, 200ms); got {text!r}")
    return check_time_span("--duration", v)


#: ``--duration``: an end time > 0 (s, ``200ms``)
duration_type = arg_type(_duration, "duration")


def _waveform(text):
    from ipmc_asym.dynamics.entry import Drive  # deferred: heavy module, start-up (the dynamic commands only)

    return Drive.parse(text).source


#: ``--waveform SPEC`` (the grammar of :func:`ipmc_asym.dynamics.waveforms.parse_waveform`) -> a Waveform
waveform_type = arg_type(_waveform, "--waveform")


def _sheet_conv(text):
    v = parse_sheet_resistance("--sheet-resistance", text)
    if not 0.0 <= v <= MAX_SHEET_RESISTANCE:
        raise ValueError(f"--sheet-resistance must be within 0..{MAX_SHEET_RESISTANCE:g} Ohm/sq (e.g. 2.5ohm/sq; a "
                         f"numerical guard: the electrode line overflows past it); got {text!r}")
    return v


#: ``--sheet-resistance``: Ohm/sq of each electrode (``2.5ohm/sq``; a bare number is Ohm/sq), >= 0
sheet_resistance_type = arg_type(_sheet_conv, "--sheet-resistance")


def frequency_type(name):
    """A frequency within ``settings.FREQUENCY_RANGE`` (Hz, ``1kHz``)."""
    def conv(text):
        v = parse_quantity(name, text, {"Hz": 1.0, "kHz": 1e3, "mHz": 1e-3, "MHz": 1e6}, "frequency")
        lo, hi = FREQUENCY_RANGE
        if v <= 0:
            raise ValueError(f"must be > 0 Hz (e.g. 0.1Hz, 1kHz); got {text!r}")  # argparse names the option
        if not lo <= v <= hi:
            raise ValueError(f"must be within {lo:g}..{hi:g} Hz (a numerical guard: the closed forms are checked "
                             f"finite there); got {text!r}")
        return v

    return arg_type(conv, name)


def add_beam_options(p, default=None):
    """``--beam`` (default the library's one, :data:`ipmc_asym.dynamics.entry.DEFAULT_BEAM`, unless a command
    has its own reason) and ``--viscous-modulus``."""
    from ipmc_asym.dynamics.entry import BEAM_CHOICES, DEFAULT_BEAM  # deferred: heavy module, start-up (the dynamic commands only)

    default = DEFAULT_BEAM if default is None else default
    p.add_argument("--beam", default=default, choices=BEAM_CHOICES,
                   help=f"strip mechanics: dynamic (inertia, Kelvin-Voigt damping, resonances) or quasi-static "
                        f"(default {default})")
    p.add_argument("--viscous-modulus", dest="viscous_modulus", type=viscous_modulus_type(), default=0.0,
                   help="Kelvin-Voigt viscous modulus eta_E (Pa s; '2kPa s'); default 0: no source gives a value")


#: the time/frequency solver option of every command: ``--solver``; the names it had per command stay aliases
SOLVER_ALIASES = {"step": "--fidelity", "freq": "--method", "fit": "--time-fidelity"}


def add_solver_option(p, command, *, dest, choices, default, help):
    """``--solver`` (and the command's older name, :data:`SOLVER_ALIASES`, writing the same ``dest``)."""
    old = SOLVER_ALIASES.get(command)
    p.add_argument("--solver", *((old,) if old else ()), dest=dest, default=default, choices=choices,
                   help=help + (f" ({old} is the same option)" if old else ""))


def _segments_conv(text):
    from ipmc_asym.dynamics.line_time import MAX_SEGMENTS  # deferred: heavy module, start-up (the dynamic commands only)

    v = count_type("--line-segments", 2)(text)
    if v > MAX_SEGMENTS:
        raise ValueError(f"--line-segments must be an integer in [2, {MAX_SEGMENTS}]; got {text!r}")
    return v


def add_line_options(p):
    """``--sheet-resistance`` and ``--line-segments`` of the time-domain electrode line (step, drive)."""
    from ipmc_asym.dynamics.line_time import DEFAULT_SEGMENTS, MAX_SEGMENTS  # deferred: heavy module, start-up (the dynamic commands only)

    p.add_argument("--sheet-resistance", dest="sheet_resistance", type=sheet_resistance_type, default=0.0,
                   help="sheet resistance of each electrode (2.5ohm/sq; a bare number is Ohm/sq; default 0 = ideal "
                        "electrodes, the uniform strip): the strip as a discretised RC line driven at the clamp "
                        "(circuit fidelity); adds the columns sigma_error and w_error (its stated error)")
    p.add_argument("--line-segments", dest="line_segments", type=arg_type(_segments_conv, "--line-segments"),
                   default=DEFAULT_SEGMENTS,
                   help=f"N: the line is run with 2N segments (reported) and N (its error estimate); default "
                        f"{DEFAULT_SEGMENTS}, at most {MAX_SEGMENTS}")


def _electrode_conv(text):
    parts = str(text).split(":")
    if len(parts) != 2:
        raise ValueError(f"--electrode must be X1:X2, the covered part of the length (e.g. 2mm:18mm); got {text!r}")
    return tuple(parse_length("--electrode", v.strip()) for v in parts)


def add_support_options(p, sensing=False):
    """``--support`` and ``--electrode`` (freq, drive); ``sensing``: also ``free``/``tip-force`` (freq --mode sensing)."""
    from ipmc_asym.beam.dynamics import SUPPORTS  # deferred: heavy module, start-up (the dynamic commands only)

    extra = ("free", "tip-force") if sensing else ()
    p.add_argument("--support", default=None, choices=SUPPORTS + extra,
                   help="strip support: clamped-free and clamped-pinned give the default outputs (free tip w, theta; "
                        "blocked tip F_block); clamped-clamped adds the clamps' reaction moments and forces M_root, "
                        "M_tip, F_root, F_tip and the midspan deflection w_mid (small displacements)"
                        + ("; with --mode sensing, how the tip displacement is imposed: free (an end moment, uniform "
                           "curvature) or tip-force (the cantilever's tip moved; the default)" if sensing else ""))
    p.add_argument("--electrode", type=arg_type(_electrode_conv, "--electrode"), default=None,
                   help="X1:X2 covered part of the length (e.g. 2mm:18mm, 0 <= X1 < X2 <= L; default the whole strip): "
                        "the active moment acts there only, the beam outputs are small-displacement")


def support_from_args(args):
    """``(support, electrode)`` checked against ``--length`` and the other options (one-line
    ValueError), before the strip is built."""
    el = args.electrode
    if el is not None:
        x1, x2 = el
        if not 0.0 <= x1 < x2 <= args.length:
            raise ValueError(f"--electrode X1:X2 must satisfy 0 <= X1 < X2 <= L = {fmt_length(args.length)}; "
                             f"got {fmt_length(x1)}:{fmt_length(x2)}")
    if el is not None or args.support == "clamped-clamped":
        what = "--support clamped-clamped" if args.support == "clamped-clamped" else "--electrode"
        if getattr(args, "sheet_resistance", None):
            raise ValueError(f"{what} is not supported with --sheet-resistance (the electrode line's moment is "
                             "distributed over the full strip, free or blocked tip)")
    return args.support, el


#: units of the clamped-clamped outputs (drive's columns; freq's amplitudes per volt)
CLAMPED_UNITS = {"M_root": "N m (reaction moment of the clamp x = 0)", "M_tip": "N m (reaction moment of the clamp x = L)",
                 "F_root": "N (force of the clamp x = 0 on the strip, +z)",
                 "F_tip": "N (force of the clamp x = L on the strip, +z; the sign of F_block)",
                 "w_mid": "m (deflection at x = L/2)"}


def print_clamped(t_name, t, rows, per=""):
    """Text table of the clamped-clamped outputs (``rows``: dict name -> values at ``t``; ``per``: "/V" for amplitudes)."""
    print(f"clamped-clamped: {t_name:>9s} {f'|M_root| [N m{per}]' if per else 'M_root [N m]':>13s} "
          f"{f'|M_tip| [N m{per}]' if per else 'M_tip [N m]':>13s} {f'|F_root| [mN{per}]' if per else 'F_root [mN]':>12s} "
          f"{f'|F_tip| [mN{per}]' if per else 'F_tip [mN]':>12s} {f'|w_mid| [mm{per}]' if per else 'w_mid [mm]':>11s}")
    for i in range(len(t)):
        r = {k: float(v[i]) + 0.0 for k, v in rows.items()}
        print(f"                 {float(t[i]):9.4g} {r['M_root']:13.5g} {r['M_tip']:13.5g} {r['F_root'] * 1e3:12.5g} "
              f"{r['F_tip'] * 1e3:12.5g} {r['w_mid'] * 1e3:11.5g}")
