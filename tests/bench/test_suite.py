"""ipmc_asym_bench on a small sweep, quick sections: JSON structure, sane error ordering, the
table and the plot (timing values are never asserted)."""

import json

import numpy as np
import pytest

from ipmc_asym.integral.api import moment
from ipmc_asym.plotting.speed import load_bench, plot_speed_accuracy
from ipmc_asym_bench.kernels import bare_driver
from ipmc_asym_bench.suite import FAST, MODELS, SECTIONS, format_table, quick_bench, run_bench, run_sections


@pytest.fixture(scope="module")
def res():
    return run_bench(points=2000, bvp_points=3, repeats=1, compile_times=False, quick_sections=True,
                     sections=["exact_api", "uq", "charge"])


def test_structure(res):
    json.dumps(res)  # JSON-ready
    assert res["points"] == 2000
    for k in ("targets", "results", "compile", "all_pass", "ranges", "threads", "sections"):
        assert k in res
    assert set(res["sections"]) == {"exact_api", "uq", "charge"}
    rows = {(r["model"], r["fidelity"]): r for r in res["results"]}
    assert set(rows) == {(m, f) for m in MODELS for f in ("leading", "corrected", "quadrature", "exact", "bvp")}
    for (m, f), r in rows.items():
        assert r["seconds_per_point_serial"] > 0
        if f == "exact":
            assert r["nonfinite"] == 0 and r["bvp_sample"] >= 1
        elif f != "bvp":
            assert r["seconds_per_point_parallel"] > 0
            assert r["nonfinite"] == 0
            assert isinstance(r["pass_time"], bool)
            assert r["bvp_sample"] >= 1


def test_error_ordering(res):
    rows = {(r["model"], r["fidelity"]): r for r in res["results"]}
    for m in MODELS:
        lead, corr, quad = (rows[(m, f)]["rel_error_max"] for f in ("leading", "corrected", "quadrature"))
        assert corr < lead and quad < lead
        assert quad < 1e-8 and corr < 1e-8
        assert lead < 0.1
        # the estimates bound the measured errors (x10 slack)
        # exact: within its stated error of the BVP (both ~1e-12 here)
        assert rows[(m, "exact")]["rel_error_max"] <= 10 * max(rows[(m, "exact")]["error_estimate_max"], 1e-12)
        for f in ("leading", "corrected", "quadrature"):
            assert rows[(m, f)]["rel_error_max"] <= 10 * max(rows[(m, f)]["error_estimate_max"], 1e-12)


def test_table_and_plot(res, tmp_path):
    t = format_table(res)
    assert "leading" in t and "quadrature" in t and "[exact_api]" in t and "[charge]" in t
    p = plot_speed_accuracy(res, tmp_path / "sa.png")
    assert (tmp_path / "sa.png").stat().st_size > 1000 and str(p).endswith("sa.png")


def test_saved_result_is_read_back(res, tmp_path):
    f = tmp_path / "b.json"
    f.write_text(json.dumps(res), encoding="utf-8")
    assert load_bench(f)["points"] == res["points"]
    f.write_text("{}", encoding="utf-8")
    with pytest.raises(ValueError, match="not the output"):
        load_bench(f)


def test_exact_api_section(res):
    """The exact/API figures are reported (values finite, each with its target)."""
    figs = res["sections"]["exact_api"]["figures"]
    whats = " | ".join(f["what"] for f in figs)
    for key in ("exact time per point", "speed-up over one BVP", "exact vs BVP", "bare driver",
                "threads", "temporaries", "scalar", "import numba"):
        assert key in whats
    for f in figs:
        assert f["value"] is not None and f["value"] == f["value"]
        assert f["target"] is not None or f["pass"] is None  # without a target: reported, not judged
    acc = next(f for f in figs if f["what"].startswith("exact vs BVP"))
    assert acc["value"] <= 1e-11  # an accuracy figure, not a timing: exact vs the BVP


def test_uq_and_charge_sections(res):
    for name in ("uq", "charge"):
        figs = res["sections"][name]["figures"]
        assert figs and all(f["value"] is not None and f["value"] > 0 for f in figs)


@pytest.mark.parametrize("fidelity", [*FAST, "exact"])
def test_bare_driver_is_the_api_kernel(fidelity):
    """The bench's driver over the public kernels gives the API's ``I`` (same kernels)."""
    th = np.geomspace(20e-6, 2e-3, 37)
    v = np.linspace(-3.0, 3.0, 37)
    for model in MODELS:
        call, outs = bare_driver(fidelity, model, th, v)
        call()
        ref = moment(th, v, model, fidelity).I
        np.testing.assert_allclose(outs[0], ref, rtol=1e-12, atol=0.0)


def test_sections_are_checked_and_quick_bench_has_no_sections():
    with pytest.raises(ValueError, match="bench section must be one of"):
        run_sections(["nope"])
    assert all(v.startswith("ipmc_asym_bench.") for v in SECTIONS.values())
    r = quick_bench(points=200, bvp_points=1)
    assert r["sections"] == {} and r["compile"] == {} and r["results"]
