"""``ipmc-asym freq``: small-signal impedance and tip-deflection/voltage transfer function."""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.registry import model_names
from ipmc_asym.base.units import fmt_length, parse_quantity
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_size_option,
    add_strip_options,
    arg_type,
    diffusion_type,
    fmt_num,
    material_from_args,
    model_help,
    strip_from_args,
)
from ipmc_asym.dynamics.circuit import FREQ_METHODS, frequency_response
from ipmc_asym.io.jsonio import dumps

#: frequencies of one run (log-spaced: 1e5 points resolve any spectrum; the --json text stays ~10 MB);
#: settable with --max-points
MAX_POINTS = 10**5


def _freq(name):
    def conv(text):
        v = parse_quantity(name, text, {"Hz": 1.0, "kHz": 1e3, "mHz": 1e-3, "MHz": 1e6}, "frequency")
        if v <= 0:
            raise ValueError(f"{name} must be > 0 Hz (e.g. 0.1Hz, 1kHz); got {text!r}")
        return v

    return arg_type(conv, name)


def register(sub):
    p = sub.add_parser("freq", help=SUMMARIES["freq"])
    add_strip_options(p, voltage=False)
    p.add_argument("--from", dest="f1", type=_freq("--from"), required=True, help="first frequency (e.g. 0.01Hz)")
    p.add_argument("--to", dest="f2", type=_freq("--to"), required=True, help="last frequency (e.g. 1kHz)")
    add_size_option(p, "--points", default=50, maximum=MAX_POINTS, minimum=2, help="log-spaced points")
    p.add_argument("--model", default="constant", choices=list(model_names()), help=model_help("constant"))
    p.add_argument("--method", default="pnp-linear", choices=FREQ_METHODS,
                   help="pnp-linear (exact linearised PNP, closed form) or circuit (R + 1/(i w C_d))")
    p.add_argument("--diffusion", type=diffusion_type(), default=None,
                   help="cation diffusion coefficient D (1e-10m2/s, 1e-6cm2/s; a bare number is m^2/s)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args):
    if args.f2 <= args.f1:
        raise ValueError(f"--to must be above --from; got {args.f1:g} Hz .. {args.f2:g} Hz")
    material = material_from_args(args)
    if args.diffusion is not None:
        material = material.with_(D=args.diffusion)
    strip = strip_from_args(args)
    f = np.geomspace(args.f1, args.f2, args.points)
    r = frequency_response(f, strip=strip, model=args.model, material=material, method=args.method)
    cols = {"f": r.f, "Z_re": r.Z.real, "Z_im": r.Z.imag, "w_amp": r.w_amp, "w_phase": r.w_phase}
    head = {"tau": r.tau, "model": r.model, "method": r.method, "thickness_total": strip.thickness,
            "electrode_area": strip.width * strip.length, "diffusion_coefficient": material.D,
            "units": {"f": "Hz", "Z": "Ohm (strip, electrode area 2l L)", "w_amp": "m/V", "w_phase": "rad"},
            "notes": r.notes + ["about phi0 = 0; w from the layers' charge, small displacements"]}
    if args.json:
        out = dict(head)
        out.update(cols)
        print(dumps(out, indent=1))
        return 0
    print(f"small signal about 0 V, model {r.model}, method {r.method}, total thickness 2e = "
          f"{fmt_length(strip.thickness)}: tau = {r.tau:.4g} s, D = {material.D:.3g} m^2/s")
    print(f"{'f [Hz]':>11s} {'Z_re [Ohm]':>12s} {'Z_im [Ohm]':>12s} {'|w|/V [mm/V]':>13s} {'phase [rad]':>11s}")
    for i in range(f.size):
        print(f"{fmt_num(f[i], '11.4g')} {fmt_num(r.Z.real[i], '12.5g')} {fmt_num(r.Z.imag[i], '12.5g')} "
              f"{fmt_num(r.w_amp[i] * 1e3, '13.5g')} {fmt_num(r.w_phase[i], '11.4g')}")
    for n in head["notes"]:
        print(f"note: {n}")
    return 0
