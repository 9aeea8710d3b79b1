"""Acceptance: a CLI fuzz test and the thickness x voltage x model grid against the BVP."""

import contextlib
import io
import json
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ipmc_asym.base.registry import model_names
from ipmc_asym.bvp.solver import solve
from ipmc_asym.cli import main
from ipmc_asym.model.params import Strip


def run_cli(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main(argv)
        except SystemExit as exc:  # argparse: usage error
            rc = exc.code
    return rc, out.getvalue(), err.getvalue()


def _no_nonfinite_result(text):
    assert not re.search(r"(?<![A-Za-z_])(nan|inf)(?![A-Za-z_])", text, re.IGNORECASE), text[:2000]


# ---------------------------------------------------------------------------------------
# fuzz: option strings and scene files
# ---------------------------------------------------------------------------------------
LENGTHS = ["200um", "2 cm", "0.02", "1mm", "10um", "-1mm", "0", "abc", "1e400", "nan", "5 furlongs", "",
           "1e-3", "2cm", "50nm", "1nm"]
VOLTS = ["1V", "-1V", "0", "-0", "500mV", "-2.5", "20V", "-20V", "1e-4", "1kV", "x", "nan", "inf", "1e400", ""]
TOLS = ["1%", "0.01", "1e-3", "5", "-1", "0", "abc", "100%", "0.5%"]
FIDS = ["leading", "corrected", "quadrature", "bogus"]
MODELS = list(model_names()) + ["all", "quadratic"]
OPTS = {
    "--length": LENGTHS, "--width": LENGTHS, "--thickness": LENGTHS, "--voltage": VOLTS,
    "--modulus": ["130MPa", "1.3e8", "-5", "0", "1GPa", "abc"], "--c-moy": ["paper", "formula", "3000", "-1", "x"],
    "--tol": TOLS, "--fidelity": FIDS, "--model": MODELS,
}


@st.composite
def option_argv(draw):
    cmd = draw(st.sampled_from(["estimate", "sweep"]))
    argv = [cmd]
    for opt in draw(st.lists(st.sampled_from(sorted(OPTS)), max_size=4, unique=True)):
        val = draw(st.sampled_from(OPTS[opt]))
        argv += [opt, val] if draw(st.booleans()) else [f"{opt}={val}"]
    if cmd == "sweep":
        var = draw(st.sampled_from(["length", "width", "thickness", "voltage", "modulus", "bogus"]))
        lo, hi = draw(st.sampled_from([("1cm", "3cm"), ("10um", "1mm"), ("-1V", "1V"), ("1e8", "2e8"),
                                       ("0", "1"), ("a", "b")]))
        n = draw(st.sampled_from(["1", "3", "0", "x", "1e20"]))
        argv += ["--vary", f"{var}={lo}:{hi}:{n}"]
    if draw(st.booleans()):
        argv.append("--json")
    return argv


def _check(rc, out, err):
    assert "Traceback" not in err and "Traceback" not in out
    assert rc in (0, 2), (rc, err)
    if rc == 2:
        # one line of refusal (plausibility warnings on other options may precede it)
        lines = [ln for ln in err.splitlines() if ln.strip() and "compiling the Numba" not in ln
                 and ": warning:" not in ln]
        assert len(lines) == 1, err
    else:
        _no_nonfinite_result(out)
        if out.lstrip().startswith("{"):
            json.loads(out, parse_constant=lambda c: pytest.fail(f"non-finite {c} in JSON"))


@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(option_argv())
def test_cli_fuzz_options(argv):
    _check(*run_cli(argv))


SCENE_VALUES = {
    "model": ['"constant"', '"affine"', '"nope"', "3"],
    "voltage": ['"1V"', '"-1V"', "0", '"x"', "1e400", '"20V"'],
    "tolerance": ["1e-3", "0.01", "0", "-1", '"a"'],
    "outputs": ['["I", "moment"]', '["I", "tip_deflection", "rotation", "blocking_force"]', '["bogus"]', "[]"],
}
STRIP_VALUES = {"thickness": ['"200um"', '"10um"', '"1nm"', '"-2um"', "[1, 2]"],
                "length": ['"2cm"', '"0"', "0.03"], "bogus": ["1"]}


@st.composite
def scene_text(draw):
    lines = []
    for k in draw(st.lists(st.sampled_from(sorted(SCENE_VALUES)), unique=True)):
        lines.append(f"{k} = {draw(st.sampled_from(SCENE_VALUES[k]))}")
    strip = draw(st.lists(st.sampled_from(sorted(STRIP_VALUES)), unique=True, max_size=2))
    if strip:
        lines.append("[strip]")
        lines += [f"{k} = {draw(st.sampled_from(STRIP_VALUES[k]))}" for k in strip]
    if draw(st.booleans()):
        lines.append("[sweep]")
        lines.append(draw(st.sampled_from([
            'length = {start = "1cm", stop = "3cm", n = 3}', 'voltage = ["0.5V", "-1V"]',
            'width = {start = "1mm", stop = "2mm"}', 'length = {start = "1cm", stop = "3cm", n = 100000000}'])))
    if draw(st.booleans()):
        lines.append("this is not toml ][")
    return "\n".join(lines) + "\n"


@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(text=scene_text(), as_json=st.booleans())
def test_cli_fuzz_scene_files(text, as_json, tmp_path_factory):
    p = tmp_path_factory.mktemp("scene") / "s.toml"
    p.write_text(text, encoding="utf-8")
    _check(*run_cli(["scene", str(p)] + (["--json"] if as_json else [])))


# ---------------------------------------------------------------------------------------
# grid: total thickness 1 um - 10 mm x voltage +-(1e-4 - 20) V x 3 models, against the BVP
# ---------------------------------------------------------------------------------------
_BVP = {}


def _bvp(m, th, v):
    key = (m, th, abs(v))
    if key not in _BVP:
        r = solve(Strip(thickness=th, voltage=abs(v)), m)
        assert r.success, r.message
        _BVP[key] = r.I
    return math.copysign(_BVP[key], v)


def _grid_point(m, th, v, extra=()):
    th, v = float(th), float(v)
    rc, out, err = run_cli(["estimate", "--json", "--model", m, f"--thickness={th!r}", f"--voltage={v!r}",
                            *extra])
    assert "Traceback" not in err
    if rc == 2:
        assert len([ln for ln in err.splitlines() if ln.strip()]) == 1, err
        return None
    assert rc == 0, err
    row = json.loads(out)["results"][0]
    ref = _bvp(m, th, v)
    rel = abs(row["I"] - ref) / abs(ref)
    return rel, row["error_estimate"]


def _grid(ths, vs):
    answered = refused = 0
    for m in model_names():
        for th in ths:
            for v in vs:
                for s in (1.0, -1.0):
                    res = _grid_point(m, th, s * v)
                    if res is None:
                        refused += 1
                    else:
                        answered += 1
                        rel, est = res
                        # default settings (quadrature, escalated past the two-term rungs' 1e-8
                        # ceiling to exact): within 1e-8 of the BVP, and never beyond the bound
                        assert rel <= 1e-8 and rel <= max(est, 1e-12), (m, th, s * v, rel, est)
                    res = _grid_point(m, th, s * v, ("--tol", "1e-8")) if s > 0 else None
                    if res is not None:
                        assert res[0] <= 1e-8, (m, th, s * v, res)
    # the grid is inside the range the package claims (>= 1 um): it must answer, not refuse
    assert refused == 0 and answered == 2 * len(model_names()) * len(ths) * len(vs)


def test_grid_against_bvp_coarse():
    _grid([1e-6, 2e-3], [1e-4, 20.0])


#: half-decades where the answer changes with the thickness (below ~30 um the layers reach the core:
#: the ladder escalates to ``exact``, the error estimate leaves its floor), decades above it, where
#: the core is neutral and every model answers alike (the nominal 200 um lies between 100 um and
#: 10 mm); both ends of the range
FINE_THICKNESSES = [*np.geomspace(1e-6, 1e-4, 5), 1e-2]
#: one voltage per layer scheme (A2 = F V/RT, the drop across both layers in thermal units): one
#: quadrature panel at each face (|Y| < 1/2, as at every voltage below ~20 mV; the smallest voltage),
#: a few doubling panels (A2 ~ 6), the anode deep in its depletion zone (A2 ~ 67), the largest
#: voltage (A2 ~ 775); both signs of each
FINE_VOLTAGES = [1e-4, 0.152, 1.74, 20.0]


@pytest.mark.slow
def test_grid_against_bvp_fine():
    _grid(FINE_THICKNESSES, FINE_VOLTAGES)
