"""``ipmc-asym bench`` at its default invocation with ``--quick`` (every section, the compile and
start-up subprocesses, the smallest sizes): JSON structure, error ordering against the BVP, the
table and the plot, and the refusals of bad input.  Timing values are never asserted."""

import json
import math
from importlib.metadata import EntryPoint

import numpy as np
import pytest

import ipmc_asym as ia
import ipmc_asym.cli as cli
from ipmc_asym.plotting.speed import load_bench, plot_speed_accuracy
from ipmc_asym_bench.kernels import seven_transcendentals
from ipmc_asym_bench.suite import MODELS, SECTIONS, format_table, quick_bench, run_sections

BENCH_EP = EntryPoint(name="bench", value="ipmc_asym_bench.cli", group=cli.PLUGIN_GROUP)


@pytest.fixture
def with_bench(monkeypatch):
    monkeypatch.setattr(cli, "entry_points", lambda **kw: [BENCH_EP] if kw.get("group") == cli.PLUGIN_GROUP else [])


# the default invocation compiles the kernels in fresh processes with a cold cache (~40 s): its tests
# are slow (run by CI); the refusals and the yardstick stay in the dev loop
@pytest.fixture(scope="module")
def res(tmp_path_factory):
    """``ipmc-asym bench --json --quick --figure F.png``: the default invocation at its smallest
    sizes, drawing its figure."""
    fig = tmp_path_factory.mktemp("bench") / "sa.png"
    mp = pytest.MonkeyPatch()
    mp.setattr(cli, "entry_points", lambda **kw: [BENCH_EP] if kw.get("group") == cli.PLUGIN_GROUP else [])
    import contextlib
    import io

    buf = io.StringIO()
    try:
        with contextlib.redirect_stdout(buf):
            rc = cli.main(["bench", "--json", "--quick", "--figure", str(fig)])
    finally:
        mp.undo()
    assert rc == 0
    out = json.loads(buf.getvalue())
    assert out["figure"] == str(fig) and fig.stat().st_size > 1000
    return out


@pytest.mark.slow
def test_default_invocation_structure(res):
    assert res["points"] == 2000 and res["bvp_points"] == 1
    for k in ("targets", "results", "compile", "all_pass", "ranges", "threads", "sections", "clock", "load", "startup"):
        assert k in res
    assert set(res["sections"]) == set(SECTIONS)
    assert res["compile"]["leading"]["compile_s"] > 0 and res["startup"]["estimate_leading_wall_s"] > 0
    rows = {(r["model"], r["fidelity"]): r for r in res["results"]}
    assert set(rows) == {(m, f) for m in MODELS for f in ("leading", "corrected", "quadrature", "exact", "bvp")}
    for (m, f), r in rows.items():
        assert r["seconds_per_point_serial"] > 0 and r["load"] == r["load"]
        if f != "bvp":
            # nonfinite: the points where the rung is invalid (NaN from moment_integral); exact
            # is valid on the whole grid
            assert r["nonfinite"] < res["points"] and isinstance(r["pass_time"], bool) and r["bvp_sample"] >= 1
            assert r["nonfinite"] == 0 or f != "exact"
            assert (r["seconds_per_point_parallel"] is None) == (f == "exact")


@pytest.mark.slow
def test_printed_targets_are_the_goals(res):
    """The targets are the project's goals (README "Speed"), not looser ones."""
    assert res["targets"]["exact"]["seconds_per_point"] == 10e-6
    figs = {f["what"]: f for sec in res["sections"].values() for f in sec["figures"]}
    over = {w: f["target"] for w, f in figs.items() if "7-transcendental loop" in w}
    assert len(over) == 6 and set(over.values()) == {1.2}
    assert figs["scalar moment_integral(2e-4, 1.0, fidelity='exact')"]["target"] == 12e-6
    assert next(f for w, f in figs.items() if w.startswith("exact time per point"))["target"] == 10e-6
    assert figs["step --fidelity circuit --tol none, 1000 time points (incl. moment and beam)"]["target"] == 10e-3
    assert figs["uq end to end at leading (sampling + 5 outputs + Sobol')"]["target"] == 1e6


@pytest.mark.slow
def test_error_ordering(res):
    rows = {(r["model"], r["fidelity"]): r for r in res["results"]}
    for m in MODELS:
        lead, corr, quad = (rows[(m, f)]["rel_error_max"] for f in ("leading", "corrected", "quadrature"))
        assert corr < lead and quad < lead
        assert quad < 1e-8 and corr < 1e-8
        assert lead < 0.1
        # the estimates bound the measured errors against the BVP (x10 slack)
        for f in ("leading", "corrected", "quadrature", "exact"):
            assert rows[(m, f)]["rel_error_max"] <= 10 * max(rows[(m, f)]["error_estimate_max"], 1e-12)


@pytest.mark.slow
def test_table_and_plot(res, tmp_path):
    t = format_table(res)
    assert "leading" in t and "quadrature" in t and "[exact_api]" in t and "[charge]" in t and "load average" in t
    p = plot_speed_accuracy(res, tmp_path / "sa.png")
    assert (tmp_path / "sa.png").stat().st_size > 1000 and str(p).endswith("sa.png")


@pytest.mark.slow
def test_saved_result_is_read_back(res, tmp_path):
    f = tmp_path / "b.json"
    f.write_text(json.dumps(res), encoding="utf-8")
    assert load_bench(f)["points"] == res["points"]
    f.write_text("{}", encoding="utf-8")
    with pytest.raises(ValueError, match="not the output"):
        load_bench(f)


@pytest.mark.slow
def test_sections_report_their_figures(res):
    """Every figure is finite where measured and carries its target or none (reported, not judged)."""
    whats = " | ".join(f["what"] for f in res["sections"]["exact_api"]["figures"])
    for key in ("exact time per point", "speed-up over one BVP", "exact vs BVP", "threads", "temporaries",
                "scalar", "import numba", "7-transcendental loop"):
        assert key in whats
    for sec in res["sections"].values():
        for f in sec["figures"]:
            assert f["target"] is not None or f["pass"] is None
            if f["value"] is not None:
                assert math.isfinite(f["value"])
                if f["target"] is not None and f["unit"] == "s":
                    assert f["pass"] == (f["value"] <= f["target"])
    acc = next(f for f in res["sections"]["exact_api"]["figures"] if f["what"].startswith("exact vs BVP"))
    assert acc["value"] <= 1e-11  # an accuracy figure, not a timing: exact vs the BVP


def test_the_yardstick_loop_computes_its_formula():
    """The 7-transcendental loop is the formula it says (numpy, independently)."""
    t = np.geomspace(1e-3, 2.0, 101)
    v = np.geomspace(1e-2, 10.0, 101)
    out = np.empty(101)
    seven_transcendentals(t, v, out)
    ref = np.exp(-v) + np.log(t) + np.expm1(-v) + np.log1p(t) + np.exp(t) + np.log(v) + np.expm1(t)
    np.testing.assert_allclose(out, ref, rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize("argv, said", [
    (["--section", "nope"], "invalid choice: 'nope' (choose from 'commands', 'exact_api'"),
    (["--points", "1e30"], "--points 1e+30 is above --max-points"),
    (["--bvp-points", "1e12"], "--bvp-points 1e+12 is above --max-bvp-points"),
    (["--points", "2.5"], "--points must be an integer"),
])
def test_bad_input_is_one_line_exit_2(with_bench, capsys, argv, said):
    with pytest.raises(SystemExit) as ex:
        rc = cli.main(["bench", *argv])
        raise SystemExit(rc)
    assert ex.value.code == 2
    err = capsys.readouterr().err.strip()
    assert said in err and "Traceback" not in err and len(err.splitlines()) <= 2


def test_sections_are_checked_and_quick_bench_has_no_sections():
    with pytest.raises(ValueError, match="bench section must be one of"):
        run_sections(["nope"])
    assert all(v.startswith("ipmc_asym_bench.") for v in SECTIONS.values())
    r = quick_bench(points=200, bvp_points=1)
    assert r["sections"] == {} and r["compile"] == {} and r["results"]
    assert {r["fidelity"] for r in r["results"]} == {"leading", "corrected", "quadrature", "exact", "bvp"}
    assert ia.moment_integral(2e-4, 1.0) > 0  # the public face the bench uses
