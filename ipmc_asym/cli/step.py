"""``ipmc-asym step``: charging transient after a voltage step (reduced model or PNP solver)."""

from __future__ import annotations

import csv
import json
import os
import sys

import numpy as np

from ipmc_asym.base.registry import model_names
from ipmc_asym.base.units import fmt_length, parse_time
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_size_option,
    add_strip_options,
    arg_type,
    diffusion_type,
    first_run_notice,
    fmt_num,
    material_from_args,
    model_help,
    strip_from_args,
)
from ipmc_asym.dynamics.circuit import STEP_FIDELITIES, step_response
from ipmc_asym.io.fileio import atomic_write, check_output_path
from ipmc_asym.io.jsonio import dumps

COLUMNS = ("t", "phi0", "sigma", "current_density", "M_A", "theta", "w")
#: output times of one run: the arrays of the integrator (~2 substeps per interval) and of the
#: forward model stay ~100 MB; settable with --max-points
MAX_POINTS = 10**5
#: the same with --fidelity pnp, whose solver keeps the profiles of every output time (~10 kB each:
#: 1e5 points reach 1 GB); applies where --max-points is left at its default
MAX_POINTS_PNP = 10**4


def sidecar_path(out: str) -> str:
    """The metadata file beside a step CSV: ``x.csv`` -> ``x.csv.json`` (tau, thickness, model, units)."""
    return out + ".json"


def _duration(text):
    v = parse_time("--duration", text)
    if v <= 0:
        raise ValueError(f"--duration must be > 0 (e.g. 0.5s, 200ms); got {text!r}")
    return v


def register(sub):
    p = sub.add_parser("step", help=SUMMARIES["step"])
    add_strip_options(p)
    p.add_argument("--duration", type=arg_type(_duration, "duration"), default=None,
                   help="end time (e.g. 0.2s, 50ms; default 5 tau)")
    p.add_argument("--fidelity", default="circuit", choices=STEP_FIDELITIES,
                   help="circuit (reduced nonlinear capacitor) or pnp (transient Nernst-Planck/Gauss)")
    p.add_argument("--model", default="constant", choices=list(model_names()), help=model_help("constant"))
    p.add_argument("--diffusion", type=diffusion_type(), default=None,
                   help="cation diffusion coefficient D (1e-10m2/s, 1e-6cm2/s; a bare number is m^2/s)")
    add_size_option(p, "--points", default=1000, maximum=MAX_POINTS, minimum=2,
                    help=f"output times (with --fidelity pnp at most {MAX_POINTS_PNP:.0e} unless --max-points is given)")
    p.add_argument("--out", default=None, metavar="F.csv",
                   help="CSV file (header row t, phi0, sigma, current_density, M_A, theta, w; SI), with the "
                        "metadata (tau, total thickness, model, units) in the sidecar F.csv.json")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args):
    if args.fidelity == "pnp" and args.max_points == MAX_POINTS and args.points > MAX_POINTS_PNP:
        raise ValueError(f"--points {args.points:g} with --fidelity pnp is above {MAX_POINTS_PNP:g} (the pnp solver keeps "
                         f"every output time's profiles: ~10 kB each); lower --points or set --max-points")
    if args.out:
        check_output_path(args.out, "file", formats=(".csv",))
        check_output_path(sidecar_path(args.out), "file")
    material = material_from_args(args)
    if args.diffusion is not None:
        material = material.with_(D=args.diffusion)
    strip = strip_from_args(args)
    first_run_notice()
    r = step_response(strip.voltage, args.duration, strip=strip, model=args.model, fidelity=args.fidelity,
                      material=material, points=args.points)
    cols = {"t": r.t, "phi0": r.phi0, "sigma": r.sigma, "current_density": r.current_density, "M_A": r.M_A,
            "theta": r.theta, "w": r.w}
    if args.out:
        # the CSV has one header row (pandas.read_csv reads it as is); the metadata goes to a
        # sidecar JSON file beside it
        meta = {"csv": os.path.basename(args.out), "tau": r.tau, "thickness_total": strip.thickness,
                "half_thickness_e": strip.e, "voltage": strip.voltage, "model": r.model, "fidelity": r.fidelity,
                "units": {"t": "s", "phi0": "V", "sigma": "C/m^2", "current_density": "A/m^2", "M_A": "N m",
                          "theta": "rad", "w": "m"}}
        with atomic_write(args.out) as fh:
            wr = csv.writer(fh)
            wr.writerow(COLUMNS)
            for i in range(r.t.size):
                wr.writerow([repr(float(cols[c][i]) + 0.0) for c in COLUMNS])
        with atomic_write(sidecar_path(args.out)) as fh:
            fh.write(json.dumps(meta, indent=1) + "\n")
        sys.stderr.write(f"step: {r.t.size} rows -> {args.out} (metadata: {sidecar_path(args.out)})\n")
    head = {"tau": r.tau, "R": r.R, "C_d0": r.C_d0, "model": r.model, "fidelity": r.fidelity,
            "voltage": strip.voltage, "thickness_total": strip.thickness, "half_thickness_e": strip.e,
            "diffusion_coefficient": material.D, "seconds": r.seconds, "notes": r.notes, "message": r.message}
    if args.json:
        out = dict(head)
        out.update({c: cols[c] for c in COLUMNS})
        print(dumps(out, indent=1))
        return 0
    if not args.out:
        print(f"step {strip.voltage:g} V, total thickness 2e = {fmt_length(strip.thickness)}, model {r.model}, "
              f"fidelity {r.fidelity}: tau = {r.tau:.4g} s (R = {r.R:.4g} Ohm m^2, C_d(0) = {r.C_d0:.4g} F/m^2, "
              f"D = {material.D:.3g} m^2/s)")
        idx = np.unique(np.linspace(0, r.t.size - 1, min(r.t.size, 11)).astype(int))
        print(f"{'t [s]':>11s} {'sigma [C/m^2]':>14s} {'J [A/m^2]':>11s} {'M_A [N m]':>11s} {'theta':>9s} {'w [mm]':>9s}")
        for i in idx:
            print(f"{fmt_num(r.t[i], '11.4g')} {fmt_num(r.sigma[i], '14.6g')} {fmt_num(r.current_density[i], '11.4g')} "
                  f"{fmt_num(r.M_A[i], '11.4g')} {fmt_num(r.theta[i], '9.4g')} {fmt_num(r.w[i] * 1e3, '9.4g')}")
        for n in r.notes:
            print(f"note: {n}")
    return 0
