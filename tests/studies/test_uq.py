"""Uncertainty propagation and Sobol' indices against answers known in closed form."""

import math

import numpy as np
import pytest

from ipmc_asym.forward.estimate import evaluate
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.studies.uq import parse_uncertain, run_uq


def _scene(uncertain, outputs, **kw):
    d = {"name": "t", "model": "constant", "voltage": "1V", "tolerance": 1e-2, "outputs": outputs,
         "strip": {"width": "5mm"}, "uncertain": uncertain}
    d.update(kw)
    return d


def test_output_of_one_input_has_exact_indices_within_ci():
    """I depends on the thickness only: S1 = ST = 1 for thickness, 0 for length and modulus."""
    sc = _scene({"thickness": {"dist": "uniform", "low": "150um", "high": "250um"},
                 "length": {"dist": "uniform", "low": "1.5cm", "high": "2.5cm"},
                 "modulus": {"dist": "lognormal", "median": "130MPa", "sigma": 0.2}},
                ["I", "moment"], strip={"width": "5mm"})
    # the closed form is over the whole distribution: samples past a quarter turn kept
    r = run_uq(sc, 2**14 * 5, fidelity="leading", keep_invalid=True)
    for out in ("I", "moment"):
        for k, exact in (("thickness", 1.0), ("length", 0.0), ("modulus", 0.0)):
            s = r.sobol[out][k]
            assert abs(s["S1"] - exact) <= s["S1_conf"] + 1e-12, (out, k, s)
            assert abs(s["ST"] - exact) <= s["ST_conf"] + 1e-12, (out, k, s)
    assert r.sobol["I"]["thickness"]["S1_conf"] < 0.05  # an informative interval, not a wide one


def test_product_of_lognormals_indices():
    """theta = -M L / (E I_p): with L, E lognormal (I fixed), Y = c L / E has closed-form indices.

    For Y = X1 X2 independent: V1 = m2^2 v1, V2 = m1^2 v2, V = (v1 + m1^2)(v2 + m2^2) - m1^2 m2^2,
    lognormal with log-sd s: m = exp(s^2/2), v = exp(s^2)(exp(s^2) - 1).
    """
    sL, sE = 0.1, 0.25
    sc = _scene({"length": {"dist": "lognormal", "median": "2cm", "sigma": sL},
                 "modulus": {"dist": "lognormal", "median": "130MPa", "sigma": sE}}, ["rotation"])
    # the closed form is over the whole distribution: samples past a quarter turn kept
    r = run_uq(sc, 2**15 * 4, fidelity="leading", keep_invalid=True)

    def mv(s):
        return math.exp(s * s / 2), math.exp(s * s) * (math.exp(s * s) - 1)

    (m1, v1), (m2, v2) = mv(sL), mv(sE)
    V = (v1 + m1**2) * (v2 + m2**2) - m1**2 * m2**2
    exact = {"length": (m2**2 * v1 / V, 1 - m1**2 * v2 / V), "modulus": (m1**2 * v2 / V, 1 - m2**2 * v1 / V)}
    for k, (s1, st) in exact.items():
        s = r.sobol["rotation"][k]
        assert abs(s["S1"] - s1) <= s["S1_conf"], (k, s, s1)
        assert abs(s["ST"] - st) <= s["ST_conf"], (k, s, st)


def test_quantiles_of_lognormal_modulus_are_exact():
    """Only E uncertain (lognormal): theta = theta_nominal * E_med / E, quantiles in closed form."""
    s = 0.2
    sc = _scene({"modulus": {"dist": "lognormal", "median": "130MPa", "sigma": s}}, ["rotation"])
    r = run_uq(sc, 2**14 * 3, fidelity="quadrature", keep_invalid=True)
    th0 = evaluate(Strip(length=0.02, width=5e-3), "constant", "quadrature", NAFION_LI)["theta"]
    z = 1.959963984540054
    q = r.summary["rotation"]
    assert q["q50"] == pytest.approx(th0, rel=2e-3)
    # theta < 0: the 2.5 % quantile is the most negative (smallest E)
    assert q["q2.5"] == pytest.approx(th0 * math.exp(z * s), rel=5e-3)
    assert q["q97.5"] == pytest.approx(th0 * math.exp(-z * s), rel=5e-3)
    assert q["mean"] == pytest.approx(th0 * math.exp(s * s / 2), rel=2e-3)


def test_escalation_by_tolerance():
    sc = _scene({"thickness": {"dist": "uniform", "low": "150um", "high": "250um"}}, ["I"], tolerance=1e-6)
    r = run_uq(sc, 1000)
    assert "leading" in r.fidelity and sum(r.fidelity.values()) == r.n_samples
    assert r.fidelity["leading"] == 0  # leading's error (~1e-3) never meets 1e-6


@pytest.mark.parametrize("table, msg", [
    ({"thickness": {"dist": "gauss", "mean": 1}}, "dist must be one of"),
    ({"thick": {"dist": "normal", "mean": 1, "sd": 1}}, "unknown parameter 'thick'"),
    ({"thickness": {"dist": "normal", "mean": "200um"}}, "missing sd"),
    ({"thickness": {"dist": "normal", "mean": "20um", "sd": "10um"}}, "mean < 6 sd"),
    ({"length": {"dist": "uniform", "low": "2cm", "high": "1cm"}}, "low < high"),
    ({"modulus": {"dist": "lognormal", "median": "130MPa", "sigma": "0.1MPa"}}, "plain number"),
])
def test_bad_uncertain_tables(table, msg):
    with pytest.raises(ValueError, match=msg) as ei:
        parse_uncertain(table)
    assert "\n" not in str(ei.value)


def test_uq_refuses_sweeps_and_profiles():
    with pytest.raises(ValueError, match="not available for sampling"):
        run_uq(_scene({"length": {"dist": "uniform", "low": "1cm", "high": "2cm"}}, ["profiles"]), 100)


def test_estimators_equal_salib():
    """The written-out estimators are SALib's first_order/total_order (Saltelli 2010, Jansen)."""
    from SALib.analyze.sobol import first_order, separate_output_values, total_order

    from ipmc_asym.studies.uq import _saltelli, _sobol_indices

    N, D = 2**10, 3
    U = _saltelli(D, N, 1)
    y = np.sin(U[:, 0] * 3) + U[:, 1] ** 2 * U[:, 2]
    ours = _sobol_indices(y, ["a", "b", "c"], N)
    z = (y - y.mean()) / y.std()
    A, B, AB, _ = separate_output_values(z, D, N, False)
    for j, k in enumerate("abc"):
        assert ours[k]["S1"] == pytest.approx(float(first_order(A, AB[:, j], B)), rel=1e-12, abs=1e-14)
        assert ours[k]["ST"] == pytest.approx(float(total_order(A, AB[:, j], B)), rel=1e-12, abs=1e-14)


def test_samples_outside_the_model_are_counted_and_left_out():
    """A wide modulus puts some samples past a quarter turn: counted, checked per sample like
    the forward model, out of the quantiles unless kept."""
    from ipmc_asym.forward.model import CHECKS, forward

    sc = _scene({"modulus": {"dist": "lognormal", "median": "130MPa", "sigma": 0.4}}, ["rotation"])
    r = run_uq(sc, 3000, fidelity="leading")
    E = r.samples["modulus"]
    f = forward(0.02, 5e-3, 200e-6, 1.0, modulus=E, fidelity="leading", escalate=False, tol=1e-2)
    for c in CHECKS:
        assert np.array_equal(r.checks[c], getattr(f, c)), c
    outside = ~f.valid
    assert r.n_outside == int(outside.sum()) > 0
    # independent: past a quarter turn is |theta| = |M| L / (E I_p) > pi/2
    assert np.array_equal(outside, np.abs(r.outputs["rotation"]) > math.pi / 2)
    assert r.summary["rotation"]["n"] == r.n_samples - r.n_outside
    assert r.summary["rotation"]["q2.5"] >= -math.pi / 2  # the statistics hold inside samples only
    k = run_uq(sc, 3000, fidelity="leading", keep_invalid=True)
    assert k.summary["rotation"]["n"] == k.n_samples and k.summary["rotation"]["q2.5"] < r.summary["rotation"]["q2.5"]


# ---- streaming: the chunked accumulators against the whole design in memory ------------------
def _in_memory(sc, samples, seed=0, fidelity=None, keep_invalid=False):
    """The whole design evaluated at once and numpy's statistics: the reference of the streamed run."""
    from ipmc_asym.forward.model import CHECKS
    from ipmc_asym.studies.uq import _saltelli, _scene_parts, _sobol_indices, _transform, evaluate_samples

    name, model, material, base, unc, outputs, tol = _scene_parts(sc)
    names = list(unc)
    D = len(names)
    base_n = 1 << max(1, math.ceil(math.log2(max(samples / (D + 2), 2))))
    U = _saltelli(D, base_n, seed)
    cols = {k: _transform(U[:, j], *unc[k]) for j, k in enumerate(names)}
    cols.update({k: np.full(U.shape[0], v) for k, v in base.items() if k not in cols})
    outs, counts, checks, _ = evaluate_samples(cols, outputs, model, material, tol, fidelity)
    valid = np.logical_and.reduce([checks[c] for c in CHECKS])
    use = np.ones_like(valid) if keep_invalid else valid
    ref = {"cols": cols, "outs": outs, "checks": checks, "valid": valid, "counts": counts, "summary": {}, "sobol": {}}
    for o in outputs:
        y = outs[o][use & np.isfinite(outs[o])]
        q = np.quantile(y, [0.025, 0.5, 0.975])
        ref["summary"][o] = {"mean": np.mean(y), "sd": np.std(y, ddof=1), "q2.5": q[0], "q50": q[1], "q97.5": q[2],
                             "n": y.size}
        Y = outs[o].reshape(base_n, D + 2)
        ok = use.reshape(base_n, D + 2).all(axis=1) & np.isfinite(Y).all(axis=1)
        ref["sobol"][o] = _sobol_indices(Y[ok].reshape(-1), names, int(ok.sum()), groups=np.flatnonzero(ok),
                                         base_n=base_n)
    return ref


_WIDE = {"modulus": {"dist": "lognormal", "median": "130MPa", "sigma": 0.4},
         "thickness": {"dist": "normal", "mean": "200um", "sd": "10um"},
         "length": {"dist": "uniform", "low": "1.8cm", "high": "2.2cm"}}


def test_design_ranges_are_the_whole_design():
    """A chunk's rows (fast-forwarded engine) are the whole design's rows; the whole design is
    the SALib layout of one scrambled Sobol' sequence of dimension 2D."""
    from scipy.stats import qmc

    from ipmc_asym.studies.uq import _design_rows, _saltelli

    D, N = 3, 2**9
    U = _saltelli(D, N, 7)
    base = qmc.Sobol(d=2 * D, scramble=True, seed=7).random_base2(9)
    A, B = base[:, :D], base[:, D:]
    ref = np.concatenate([A[:, None]] + [np.where(np.arange(D) == j, B, A)[:, None] for j in range(D)] + [B[:, None]],
                         axis=1).reshape(-1, D)
    np.testing.assert_array_equal(U, np.clip(ref, 0.25 / N, 1 - 0.25 / N))
    for g0, g1 in ((0, 1), (3, 130), (511, 512)):
        np.testing.assert_array_equal(_design_rows(D, N, 7, g0, g1), U[g0 * (D + 2):g1 * (D + 2)])


@pytest.mark.parametrize("keep", [False, True])
def test_streamed_statistics_equal_the_in_memory_ones(keep):
    """Many chunks (groups split across batches and chunks, samples left out): moments and
    Sobol' indices with their intervals equal numpy/_sobol_indices on the whole design to
    rounding; quantiles exactly np.quantile (the sketch still holds every value); counts equal."""
    sc = _scene(_WIDE, ["rotation", "tip_deflection", "blocking_force"])
    ref = _in_memory(sc, 5000, seed=3, keep_invalid=keep)
    r = run_uq(sc, 5000, seed=3, chunk_rows=703, keep_invalid=keep)
    assert r.n_outside == int((~ref["valid"]).sum()) > 0
    assert r.outside_by_check == {c: int((~v).sum()) for c, v in ref["checks"].items()}
    assert {k: v for k, v in r.fidelity.items() if v} == {k: v for k, v in ref["counts"].items() if v}
    for o, s in ref["summary"].items():
        got = r.summary[o]
        assert got["n"] == s["n"]
        assert got["mean"] == pytest.approx(s["mean"], rel=1e-12)
        assert got["sd"] == pytest.approx(s["sd"], rel=1e-9)
        for q in ("q2.5", "q50", "q97.5"):
            assert got[q] == s[q] and got[q + "_interval"] == [s[q], s[q]]
        assert got["quantile_rank_error"] == 0
        for k, v in ref["sobol"][o].items():
            for key in ("S1", "S1_conf", "ST", "ST_conf"):
                assert r.sobol[o][k][key] == pytest.approx(v[key], rel=1e-9, abs=1e-12), (o, k, key)


@pytest.mark.parametrize("samples, kw, most", [(20000, {"chunk_rows": 1500, "sketch_k": 64}, 0.1),
                                               (2**16 * 5, {"fidelity": "leading"}, 1e-4)])
def test_streamed_quantiles_within_their_stated_interval(samples, kw, most):
    """A compacted sketch (a small one many times; the default one past 2^15 values): the
    exact np.quantile of the same samples lies in each reported interval, and the estimate
    within the stated rank error of it."""
    sc = _scene(_WIDE, ["rotation", "moment"])
    ref = _in_memory(sc, samples, seed=1, fidelity=kw.get("fidelity"))
    r = run_uq(sc, samples, seed=1, **kw)
    valid = ref["valid"]
    for o, s in ref["summary"].items():
        got = r.summary[o]
        assert 0 < got["quantile_rank_error"] < most
        y = np.sort(ref["outs"][o][valid])
        for q, p in (("q2.5", 0.025), ("q50", 0.5), ("q97.5", 0.975)):
            lo, hi = got[q + "_interval"]
            assert lo <= s[q] <= hi, (o, q)
            e = got["quantile_rank_error"] + 1 / y.size
            assert np.quantile(y, max(p - e, 0)) <= got[q] <= np.quantile(y, min(p + e, 1)), (o, q)


def test_stored_rows_are_the_first_groups():
    sc = _scene(_WIDE, ["rotation"])
    ref = _in_memory(sc, 3000, seed=2)
    r = run_uq(sc, 3000, seed=2, chunk_rows=100, store_samples=52)  # 10 whole groups of 5 rows
    assert r.n_stored == 50 and r.n_samples > 50
    for k in _WIDE:
        np.testing.assert_array_equal(r.samples[k], ref["cols"][k][:50])
    np.testing.assert_array_equal(r.outputs["rotation"], ref["outs"]["rotation"][:50])
    np.testing.assert_array_equal(r.valid, ref["valid"][:50])
    assert r.as_dict()["outside_by_check"] == {c: int((~v).sum()) for c, v in ref["checks"].items()}


def test_peak_memory_does_not_grow_with_samples():
    """tracemalloc peak of run_uq at N and 8N base points (leading, every per-sample row
    beyond 4096 dropped): the chunks bound it, not N."""
    import tracemalloc

    sc = _scene({"thickness": {"dist": "normal", "mean": "200um", "sd": "8um"}}, ["I", "rotation"])
    run_uq(sc, 3000, fidelity="leading")  # warm: kernels, imports
    peaks = []
    for n in (2**15 * 3, 2**18 * 3):  # 2 and 12 chunks of 2^16 rows
        tracemalloc.start()
        run_uq(sc, n, fidelity="leading", store_samples=4096)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    assert peaks[1] < 1.5 * peaks[0], peaks


def test_nominal_point_outside_the_model_is_refused_before_sampling(monkeypatch):
    """A 6 cm strip at 1 V turns past a quarter turn (evaluate says so, independently of uq): uq
    refuses at once, naming the check, without sampling; --keep-invalid samples it anyway."""
    import ipmc_asym.studies.uq as uqmod

    sc = _scene({"length": {"dist": "uniform", "low": "5.5cm", "high": "6.5cm"}}, ["rotation"])
    row = evaluate(Strip(length=0.06, width=5e-3), "constant", "leading", NAFION_LI)
    assert not row["checks"]["beam_regime"]
    calls = []
    monkeypatch.setattr(uqmod, "imap_chunks", lambda *a, **k: calls.append(a) or iter(()))
    with pytest.raises(ValueError, match=r"nominal point \(length = 0\.06\).*beam_regime"):
        run_uq(sc, 64, fidelity="leading")
    assert calls == []
    inside = _scene({"length": {"dist": "uniform", "low": "1.5cm", "high": "2.5cm"}}, ["rotation"])
    uqmod.check_nominal("constant", NAFION_LI, {"length": 0.02, "width": 5e-3, "thickness": 200e-6, "voltage": 1.0,
                                                "modulus": NAFION_LI.E, "c_moy": NAFION_LI.C_moy},
                        parse_uncertain(inside["uncertain"]), 1e-2, "leading")


def test_spread_is_the_range_of_the_runs_of_each_model():
    """spread=True: each statistic's min/max over three separate runs, one per permittivity model
    (same design and seed), and the scene's own model's statistics unchanged."""
    sc = _scene({"modulus": {"dist": "lognormal", "median": "130MPa", "sigma": 0.1}}, ["rotation", "I"])
    r = run_uq(sc, 64, fidelity="quadrature", keep_invalid=True, spread=True)
    runs = {m: run_uq({**sc, "model": m}, 64, fidelity="quadrature", keep_invalid=True)
            for m in ("constant", "linear", "affine")}
    assert r.summary == runs["constant"].summary
    sp = r.model_spread
    assert sp["refused"] == {} and "model_spread" in r.as_dict()
    for o in ("rotation", "I"):
        for st in ("mean", "sd", "q2.5", "q50", "q97.5"):
            vals = [runs[m].summary[o][st] for m in runs]
            assert sp["quantities"][o][st]["min"] == min(vals) and sp["quantities"][o][st]["max"] == max(vals)
    assert "model_spread" not in runs["linear"].as_dict()  # asked for only


def test_cli_uq_spread_text_and_json(tmp_path, capsys):
    """uq --spread: the text names the spread per output; the JSON's min/max bracket the scene's
    own model's statistics (one of the three runs)."""
    import json

    from ipmc_asym.cli import main

    sc = tmp_path / "u.toml"
    sc.write_text('name = "n"\nmodel = "constant"\nvoltage = "1V"\noutputs = ["I"]\n[uncertain]\n'
                  'thickness = {dist = "uniform", low = "180um", high = "220um"}\n')
    base = ["uq", str(sc), "--samples", "128", "--fidelity", "quadrature", "--keep-invalid"]
    assert main(base + ["--spread"]) == 0
    assert "model-form spread" in capsys.readouterr().out
    assert main(base + ["--spread", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    q = d["model_spread"]["quantities"]["I"]["mean"]
    assert q["min"] <= d["summary"]["I"]["mean"] <= q["max"] and set(q["values"]) == {"constant", "linear", "affine"}
    assert main(base + ["--json"]) == 0
    assert "model_spread" not in json.loads(capsys.readouterr().out)
