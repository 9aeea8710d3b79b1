"""validate: the one verdict function on known numbers, the table mechanics, and the report's
numbers against independent computations (SymPy, the laws command, exact beam relations)."""

import json
import math
import re
from dataclasses import replace
from pathlib import Path

import pytest

from ipmc_asym.validation.validate import (
    CLAIMS,
    VERDICTS,
    Claim,
    Criterion,
    Ours,
    claims,
    criterion_text,
    judge,
)


@pytest.fixture(scope="module")
def rows():
    return {r["key"]: r for r in claims()}


# --- the verdict function -------------------------------------------------------------------
@pytest.mark.parametrize("c, paper, value, verdict", [
    (Criterion("rounds", None, ""), "38.7", 38.7499, "reproduced"),
    (Criterion("rounds", None, ""), "38.7", 38.7501, "differs"),
    (Criterion("rounds", None, ""), "3082", 3162.5, "differs"),
    (Criterion("rel", 0.05, ""), 2.0, 2.099, "reproduced"),
    (Criterion("rel", 0.05, ""), 2.0, 2.101, "differs"),
    (Criterion("factor", 2.0, ""), 0.2, 0.0999, "differs"),
    (Criterion("factor", 2.0, ""), 0.2, 0.3999, "reproduced"),
    (Criterion("abs", 0.05, ""), 1.26, {"a": 1.30, "b": 1.00}, "partly"),
    (Criterion("abs", 0.05, ""), 1.26, {"a": 1.0, "b": float("nan")}, "differs"),
    (Criterion("inside", None, ""), (0.5, 1.5), {"x": 0.7, "y": 1.4}, "reproduced"),
    (Criterion("overlap", None, ""), (0.5, 1.5), (1.6, 3.0), "differs"),
    (Criterion("overlap", None, ""), (0.5, 1.5), (1.4, 3.0), "reproduced"),
    (Criterion("at_most", None, ""), 0.01, {"a": 0.009, "b": 0.011}, "partly"),
    (Criterion("at_least", 0.5, ""), None, 0.1, "differs"),
    (Criterion("at_least", None, ""), 0.99, {"a": 0.9997, "b": 0.99}, "reproduced"),  # more linear than claimed
    (Criterion("at_least", None, ""), 0.955, 0.95, "differs"),
    (Criterion("none", None, ""), 2, None, "not-reproducible"),
    (Criterion("rel", 1e-9, ""), {"a": 1.5, "b": 3.0}, {"a": 4.5, "b": 3.0}, "partly"),
])
def test_judge(c, paper, value, verdict):
    assert judge(c, paper, value) == verdict


def test_criterion_text_states_the_condition():
    c = Criterion("at_most", None, "why", "points past the quarter turn included")
    assert criterion_text(c, 0.01).endswith("; points past the quarter turn included")
    assert criterion_text(Criterion("none", None, "why", "no source"), None) == "none: no source"


def test_unknown_criterion_kind_is_refused():
    with pytest.raises(ValueError, match="criterion kind"):
        judge(Criterion("roughly", None, ""), 1.0, 1.0)


def test_adding_a_claim_is_one_entry():
    extra = Claim("test_claim", "§0", "x = {:g}", 1.04, lambda ctx: Ours(1.0, "x = 1"),
                  Criterion("rel", 0.05, "test"))
    far = replace(extra, key="far", paper=1.1)
    out = {r["key"]: r for r in claims(table=(extra, far))}
    assert out["test_claim"]["verdict"] == "reproduced" and out["far"]["verdict"] == "differs"
    assert out["test_claim"]["claim"] == "x = 1.04"
    assert out["test_claim"]["criterion"] == criterion_text(extra.criterion, 1.04)


# --- the report ------------------------------------------------------------------------------
def test_every_row_has_a_criterion_and_a_computed_verdict(rows):
    assert len(rows) == len(CLAIMS)
    for r in rows.values():
        assert r["criterion"] and r["reason"], r["key"]
        # not-reproducible exactly where no comparison is possible
        assert (r["verdict"] == "not-reproducible") == r["criterion"].startswith("none"), r["key"]
        assert r["verdict"] in VERDICTS


def test_slip2_prefactors_are_the_sympy_factor_three(rows):
    # independent: derivations/scaling.py (SymPy) gives the ratio section 3-4 / section 6.2
    from ipmc_asym.studies.laws import factor_three

    ratios = [float(eval(v)) for v in factor_three().values()]  # noqa: S307 - SymPy rationals as text
    claim = next(c for c in CLAIMS if c.key == "slip2_prefactor")
    val = rows["slip2_prefactor"]["value"]
    for k, p in claim.paper.items():
        assert val[k] / p == pytest.approx(ratios[0], rel=1e-9)
    assert set(ratios) == {ratios[0]}
    assert rows["slip2_prefactor"]["verdict"] == ("differs" if ratios[0] != 1 else "reproduced")


def test_accumulation_widths_are_the_linear_exact_solution(rows):
    # linear model, exact (derivations/model.py: linear_exact_solution): C - 1 = (B1 - 1) sinh(z/z0)/sinh(1/z0),
    # B1 = 2/(1 + e^-A2); near the cathode C - 1 ~ (B1 - 1) exp(-x/z0), x = 1 - z
    from ipmc_asym.model.params import NAFION_LI, Strip, make_groups
    from ipmc_asym.model.permittivity import MODELS

    s = Strip()
    g = make_groups(s, NAFION_LI, MODELS["linear"].eps0, MODELS["linear"].deps)
    z0 = math.sqrt(g.A0 / g.A2)
    b1m1 = 2 / (1 + math.exp(-g.A2)) - 1
    r = rows["layer_accumulation_linear"]
    # 1 % level (judged): (B1 - 1) e^{-x/z0} = 0.01; 1/e decay length (alternative): x = z0
    assert r["value"] == pytest.approx(z0 * math.log(b1m1 / 0.01) * s.e * 1e6, rel=2e-3)
    assert r["alternatives"]["1/e decay length"]["value"] == pytest.approx(z0 * s.e * 1e6, rel=2e-3)
    for mm in ("constant", "linear", "affine"):
        rr = rows[f"layer_accumulation_{mm}"]
        assert "0.01" in rr["criterion"] and "1/e" in rr["criterion"], mm


def test_every_exclusion_is_stated_in_the_criterion(rows):
    # the rows whose numbers leave points out or pick a definition say so in the criterion itself
    for key, words in {"block_1pct": "quarter turn", "w_L": "quarter turn", "w_e": "200-800", "anode_D_steepness": "90%-10%",
                       "I_e": "local exponent", "lit_w_constant": "nominal geometry",
                       "w_phi_const_linear_r": "Pearson", "F_phi_const": "10 points",
                       "capacitance_permittivity": "eps_moy", "characteristic_time": "Li+"}.items():
        assert words in rows[key]["criterion"], (key, rows[key]["criterion"])


def test_I_e_is_a_local_exponent_not_an_endpoint_difference(rows):
    # independent: the exact moment at 2e(1 +- 1e-4) around the thinnest point of the laws span
    from ipmc_asym.integral.api import moment

    th, h = 10e-6, 1e-4
    up, dn = (abs(float(moment(th * math.exp(s), 1.0, "linear", "exact").I)) for s in (h, -h))
    local = (math.log(up) - math.log(dn)) / (2 * h)
    assert rows["I_e"]["alternatives"]["2e = 10 um - 4 mm"]["value"]["linear"] == pytest.approx(local, abs=1e-4)


def test_characteristic_time_follows_the_one_criterion(rows):
    from ipmc_asym.studies.charge_studies import D_LI_NAFION_REPORTED, TIME_CRITERION, charge_claims

    r = rows["characteristic_time"]
    assert TIME_CRITERION == r["reason"]
    study = {x["key"]: x for x in charge_claims()}["characteristic_time"]
    assert study["verdict"] == r["verdict"] and study["criterion"] == TIME_CRITERION
    if not D_LI_NAFION_REPORTED:
        assert r["verdict"] == "not-reproducible"
    # t ~ 1/D: the D for tau = 1 s is D tau(D); tau = e lambda_D / D (the test's own formula)
    from ipmc_asym.model.params import NAFION_LI, Strip, debye_length
    from ipmc_asym.model.permittivity import MODELS

    s = Strip()
    for mm in ("constant", "linear", "affine"):
        lam = float(debye_length(s.thickness, MODELS[mm].eps_moy, NAFION_LI))
        assert r["value"][f"D for tau = 1 s: {mm}"] == pytest.approx(s.e * lam * s.e, rel=1e-9)  # lam in units of e


def test_slip3_interval_is_the_mechanics_ratio(rows):
    # w_p / F^p = L^3 / (3 E I_p): cantilever with an end moment vs end force, exact
    L, E, Ip = 0.02, 1.3e8, 4 / 3 * 2.5e-3 * (100e-6) ** 3
    lo, hi = rows["slip3_ranges"]["value"]
    assert lo == pytest.approx(0.6e-3 * L ** 3 / (3 * E * Ip) * 1e3, rel=1e-12)
    assert hi == pytest.approx(1.3e-3 * L ** 3 / (3 * E * Ip) * 1e3, rel=1e-12)


def test_no_sentence_contradicts_laws(rows):
    from ipmc_asym.studies.laws import law_ranges

    ex = law_ranges("constant")["exponent_phi0"]
    m = re.search(r"([+-]\d\.\d+) at 1 V, ([+-]\d\.\d+) \.\. ([+-]\d\.\d+)", rows["I_phi_half"]["ours"])
    assert m, rows["I_phi_half"]["ours"]
    assert [float(x) for x in m.groups()] == pytest.approx([ex["at_1V"], ex["min"], ex["max"]], abs=1e-3)


def test_phi0_exponents_are_judged_on_several_ranges(rows):
    for key in ("w_phi_const", "F_phi_const", "I_phi_half", "linear_M"):
        assert len(rows[key]["value"]) >= 3, key
    # the large-displacement w where the paper plots w: w < w_p, so its exponent is below the
    # small-displacement one (theta = -M L/EI ~ w_p) on every range
    for rng, e in rows["w_phi_const"]["value"].items():
        assert e < rows["F_phi_const"]["value"][rng], rng


def test_large_3mm_is_the_beam_threshold(rows):
    # |w| where w_p/w - 1 = 1 %: solve u^2/sin^2 u - 1 = 0.01 (u = kL/2) by bisection here
    lo, hi = 1e-3, 1.0
    for _ in range(100):
        u = 0.5 * (lo + hi)
        lo, hi = (u, hi) if u * u / math.sin(u) ** 2 - 1 < 0.01 else (lo, u)
    kl = 2 * u
    assert rows["large_3mm"]["value"] == pytest.approx((1 - math.cos(kl)) / kl * 0.02 * 1e3, rel=1e-3)


def test_cli_json_and_markdown(capsys, tmp_path):
    from ipmc_asym.cli import main

    out = tmp_path / "r.md"
    assert main(["validate", "--json", "--out", str(out)]) == 0
    d = json.loads(capsys.readouterr().out)
    assert len(d["claims"]) == len(CLAIMS)
    for r in d["claims"]:
        assert {"claim", "section", "paper", "ours", "verdict", "criterion", "key", "value", "alternatives"} <= set(r)
        # a number (or numbers) wherever the paper gives one to compare
        assert (r["value"] is None) <= (r["verdict"] == "not-reproducible"), r["key"]
    assert out.read_text().count("\n| ") == len(CLAIMS) + 1  # header + one row per claim


# --- golden verdicts: a change of verdict is a reviewed diff ---------------------------------
GOLDEN = Path(__file__).resolve().parent / "golden" / "validate_verdicts.json"


def test_verdicts_match_the_golden_file(rows, request):
    """Every claim's verdict (and its alternatives') as pinned in ``tests/validation/golden/validate_verdicts.json``.

    ``pytest --update-golden tests/validation/test_validate.py`` rewrites the file; the diff is then
    reviewed like a change of code (as ``ipmc-asym derive --check`` does for the kernels)."""
    now = {k: r["verdict"] for k, r in sorted(rows.items())}
    # the verdicts under the alternative readings are pinned too ("key / reading")
    now.update({f"{k} / {alt}": a["verdict"] for k, r in rows.items() for alt, a in r["alternatives"].items()})
    if request.config.update_golden:
        text = json.dumps(now, indent=1, sort_keys=True) + "\n"
        GOLDEN.write_text(text, encoding="utf-8")
        pytest.skip("golden file rewritten")
    pinned = json.loads(GOLDEN.read_text(encoding="utf-8"))
    changed = {k: (pinned.get(k), now.get(k)) for k in set(pinned) | set(now) if pinned.get(k) != now.get(k)}
    assert not changed, f"verdicts changed (pinned, now): {changed}; rerun with --update-golden if intended"


def test_design_states_the_accumulation_lengths_measured(rows):
    # docs/design.md quotes both definitions' lengths: they must be what validate measures
    text = " ".join((Path(__file__).resolve().parents[2] / "docs" / "design.md").read_text(encoding="utf-8").split())
    m = re.search(r"devoid zone \((\d\.\d+) / (\d\.\d+) / (\d\.\d+) µm .*?decay length, (\d\.\d+) / (\d\.\d+) / (\d\.\d+) µm", text)
    assert m, "design.md no longer quotes the accumulation lengths"
    for i, mm in enumerate(("constant", "linear", "affine")):
        r = rows[f"layer_accumulation_{mm}"]
        for text_v, v in ((m.group(1 + i), r["value"]), (m.group(4 + i), r["alternatives"]["1/e decay length"]["value"])):
            dec = len(text_v.split(".")[1])
            assert abs(v - float(text_v)) <= 0.5 * 10.0 ** -dec * (1 + 1e-9), (mm, text_v, v)
def test_neglected_terms_rows_against_the_bvp(rows):
    """The pressure-term and porosity rows from independent solves (the BVP with and without it)."""
    from ipmc_asym.bvp.pressure import solve_pressure
    from ipmc_asym.bvp.solver import solve
    from ipmc_asym.model.groups import pressure_beta
    from ipmc_asym.model.params import NAFION_LI, Strip

    s, m = Strip(), NAFION_LI
    beta = float(pressure_beta(m))
    pv = rows["pressure_term"]["value"]
    por = rows["porosity_variation"]["value"]
    for mm in ("constant", "affine"):
        off = solve(s, mm, m)
        on = solve_pressure(s, mm, m, beta=beta)
        assert pv[f"{mm}: I, M_A"] == pytest.approx(100 * abs(on.I / off.I - 1), rel=1e-6)
        assert pv[f"{mm}: cathode face"] == pytest.approx(100 * abs(beta) * (off.B1 + off.groups.A3), rel=1e-9)
        M_A = off.groups.A5 * off.I
        EI = m.E * s.I_p
        assert por[mm] == pytest.approx(100 * (1 - m.phi4) * s.e * abs(M_A) / EI, rel=1e-8)
    assert rows["pressure_term"]["verdict"] == "differs"


# --- symmetric criteria, rows kinds, the section 6.1 steepness rows -------------------------
def test_correlation_rows_are_symmetric_with_the_one_sided_reading_beside_them(rows):
    # independent: Pearson r of the rows' own value against the paper's digits, both ways
    for key, paper in (("w_phi_const_linear_r", 0.99), ("F_phi_const_linear_r", 0.955)):
        r = rows[key]
        half = 0.005 if paper == 0.99 else 0.0005
        ok = [abs(v - paper) <= half for v in r["value"].values()]
        assert r["verdict"] == ("reproduced" if all(ok) else "partly" if any(ok) else "differs"), key
        alt = r["alternatives"]["r >= paper (one-sided)"]
        assert alt["criterion"].startswith("ours >= paper"), alt
        assert alt["verdict"] == ("reproduced" if all(v >= paper for v in r["value"].values()) else "partly"
                                  if any(v >= paper for v in r["value"].values()) else "differs")
        assert "one-sided" in r["criterion"]


def test_the_tally_counts_claims_apart_from_inputs_and_findings(rows):
    from ipmc_asym.validation.validate import tally

    t = tally(list(rows.values()))
    kinds = {r["kind"] for r in rows.values()}
    assert kinds == {"claim", "input", "finding"}
    for k in ("A2", "A3", "A5", "slip1_cmoy", "alpha_reading"):
        assert rows[k]["kind"] == "input", k
    assert rows["capacitance_apparent"]["kind"] == "finding"
    assert sum(t["claim"].values()) == sum(r["kind"] == "claim" for r in rows.values())
    assert sum(sum(n.values()) for n in t.values()) == len(rows)


def test_w_e_is_judged_on_the_span_of_the_I_e_row_with_each_sub_range_beside_it(rows):
    # independent: a least-squares line through ln|w| against ln e on 2e = 100-800 um, straight from sweep
    import numpy as np

    from ipmc_asym.base.settings import OUTSIDE_REGIMES
    from ipmc_asym.studies.sweeps import sweep

    arr = sweep({"thickness": np.linspace(100e-6, 800e-6, 16)}, ["linear"], "quadrature")
    ok = ~np.isin(arr["regime"], OUTSIDE_REGIMES)
    slope = np.polyfit(np.log(arr["thickness"][ok]), np.log(np.abs(arr["w"][ok])), 1)[0]
    r = rows["w_e"]
    assert r["value"]["linear"] == pytest.approx(slope, abs=1e-9)
    assert set(r["alternatives"]) == {"2e = 100-400 um", "2e = 200-800 um"}
    assert "100-800" in r["criterion"]


def test_anode_and_cathode_steepness_rows_read_the_90_10_width(rows):
    # independent: the 90-10 % width of D_bar from each face, found by bisection on a cubic interpolant of
    # the BVP profile (not transition_width's piecewise-linear first crossing)
    import numpy as np
    from scipy.interpolate import PchipInterpolator

    from ipmc_asym.model.params import Strip
    from ipmc_asym.studies.profiles import profile

    s = Strip()

    def width(res, face):
        z, f = (res.z, res.D) if face == "anode" else (-res.z[::-1], res.D[::-1])
        core = float(np.interp(0.0, z, f))
        with np.errstate(over="ignore"):  # PCHIP's harmonic mean of slopes overflows at the steep face
            g = PchipInterpolator(z, (f - core) / (f[0] - core))
        lv = [_bisect(lambda x: g(x) - lev, -1.0, 0.0) for lev in (0.9, 0.1)]  # noqa: B023
        return (lv[1] - lv[0]) * s.e * 1e6

    res = {m: profile(m, s) for m in ("constant", "affine")}
    assert rows["anode_D_steepness"]["value"] == pytest.approx(
        width(res["affine"], "anode") / width(res["constant"], "anode"), rel=2e-2)
    assert rows["cathode_steeper_20x"]["value"]["induction: affine"] == pytest.approx(
        width(res["affine"], "cathode") / width(res["constant"], "cathode"), rel=2e-2)
    # the slope reading (alternative): dD/dz = C - 1 = -1 at a devoid anode face for both models
    assert rows["anode_D_steepness"]["alternatives"]["slope at the face"]["value"] == pytest.approx(1.0, abs=1e-3)
    assert rows["anode_D_values"]["value"] == pytest.approx(float(res["affine"].D[0] / res["constant"].D[0]))


def _bisect(f, a, b):
    """First root of ``f`` on [a, b] by a fine scan then bisection (f changes sign once near the face)."""
    import numpy as np

    x = np.linspace(a, b, 400001)
    y = f(x)
    k = int(np.nonzero(np.sign(y[:-1]) != np.sign(y[1:]))[0][0])
    lo, hi = x[k], x[k + 1]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if np.sign(f(mid)) == np.sign(f(lo)):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
