"""``ipmc-asym profiles``: C, phi, D, E, rhoZ, p through the thickness (paper Figs 4-7)."""

from __future__ import annotations

import math

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.registry import model_choices, model_names
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_output_option,
    add_strip_options,
    fmt_num,
    material_from_args,
    new_dir_removed_on_failure,
    strip_from_args,
)
from ipmc_asym.io.fileio import check_output_path, make_output_dir
from ipmc_asym.studies.profiles import LAYER_WIDTHS, PAPER_LAYERS, compute_all, profile_summary


def register(sub):
    p = sub.add_parser("profiles", help=SUMMARIES["profiles"])
    add_strip_options(p, mechanics=False)
    p.add_argument("--model", default="all", choices=model_choices(), help="permittivity model (default all)")
    add_output_option(p, "--out", kind="dir", default=None, metavar="DIR",
                   help="output directory for the CSV and PNG files (only its last level is created); without it "
                        "the layer summary is printed and no file is written")
    p.add_argument("--json", action="store_true", help="print the layer summary as JSON")
    p.add_argument("--format", default="png", choices=("png", "pdf", "svg"),
                   help="file format of the figures with --out (pdf, svg: vector; default png)")


def run(args) -> int:
    strip = strip_from_args(args)
    mat = material_from_args(args)
    models = model_names() if args.model == "all" else (args.model,)
    if args.out is None:
        out = {"summaries": [profile_summary(m, strip, mat, res=r) for m, r in compute_all(models, strip, mat).items()],
               "files": []}
    else:
        check_output_path(args.out, "dir")
        from ipmc_asym.plotting.profiles import write_all  # deferred: matplotlib (start-up)

        with new_dir_removed_on_failure(args.out):
            make_output_dir(args.out)
            out = write_all(args.out, models, strip, mat, fmt=args.format)
    if args.json:
        print(dumps(out, indent=2))
        return 0
    print(f"profiles at L={strip.length:g} m, total thickness 2e={strip.thickness:g} m (half e={strip.e:g} m), "
          f"phi0={strip.voltage:g} V; layer widths in µm from the face")
    print(f"{'model':9s} {'devoid':>8s} {'depletion':>10s} {'accum(1/e)':>10s} {'accum(1/2)':>10s} {'B1':>9s} "
          f"{'Debye':>8s} {'paper dep':>9s} {'paper acc':>9s}")
    def width(s, k, spec):
        # a level never crossed (a small voltage's layer changes C_bar by less than the level): n/a, not NaN
        v = s[k]
        return fmt_num(None if v is None or math.isnan(v) else v, spec).rjust(int(spec.split(".")[0]))

    for s in out["summaries"]:
        pd = PAPER_LAYERS.get((s["model"], "depletion"))
        pa = PAPER_LAYERS.get((s["model"], "accumulation"))
        print(f"{s['model']:9s} {width(s, 'devoid_um', '8.4g')} {width(s, 'depletion_um', '10.4g')} "
              f"{width(s, 'accumulation_um', '10.4g')} {width(s, 'accumulation_half_um', '10.4g')} {s['B1']:9.4g} "
              f"{s['debye_um']:8.3g} "
              f"{fmt_num(pd, '9.3g') if pd is not None else '-':>9s} {fmt_num(pa, '9.3g') if pa is not None else '-':>9s}")
    if any(s[k] is None or math.isnan(s[k]) for s in out["summaries"] for k in LAYER_WIDTHS if k in s):
        print("n/a: the profile never crosses that width's level (here C_bar changes by less than it); "
              "the levels: ipmc_asym.studies.profiles.LAYER_WIDTHS")
    from ipmc_asym.bvp.solver import min_voltage  # deferred: SciPy (start-up); the profiles have loaded it

    if 0.0 < abs(strip.voltage) < min_voltage(mat):
        print(f"note: |phi0| is below the {min_voltage(mat):.3g} V the BVP resolves: these are the Debye-Hueckel "
              f"profiles (leading order in A2 = |phi0|/V_T, relative error about A2)")
    for f in out["files"]:
        print("wrote", f)
    if args.out is None:
        print("no files written (--out DIR writes the profiles as CSV and PNG)")
    return 0
