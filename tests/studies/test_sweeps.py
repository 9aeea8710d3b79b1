import numpy as np
import pytest

from ipmc_asym.forward.estimate import evaluate
from ipmc_asym.model.params import Strip
from ipmc_asym.studies.fits import fit_power_law, sweep_fits
from ipmc_asym.studies.sweeps import iter_sweep, parse_vary, sweep


def test_parse_vary():
    k, v = parse_vary("length=1cm:4cm:16")
    assert k == "length" and v.size == 16 and v[0] == pytest.approx(0.01) and v[-1] == pytest.approx(0.04)
    k, v = parse_vary("thickness=10um:1mm:3:log")
    assert np.allclose(v, [1e-5, 1e-4, 1e-3])
    for bad in ("foo=1:2:3", "length=1cm:2cm", "length=1cm:2cm:x", "length"):
        with pytest.raises(ValueError):
            parse_vary(bad)


@pytest.mark.parametrize("model", ["constant", "affine"])
def test_sweep_rows_match_evaluate(model):
    arr = sweep({"length": [0.01, 0.03], "voltage": [0.5, 2.0]}, model=model)
    assert arr.size == 4
    for rec in arr:
        s = Strip(length=float(rec["length"]), voltage=float(rec["voltage"]))
        ev = evaluate(s, model, on_invalid="nan")
        for k in ("I", "M_A", "theta", "w", "w_small", "F_block_small"):
            if ev[k] is not None:  # withheld by a failed beam check in evaluate
                assert rec[k] == pytest.approx(ev[k], rel=1e-12)
        if ev["F_block"] is not None:
            assert rec["F_block"] == pytest.approx(ev["F_block"], rel=1e-10)
        assert rec["regime"] == ev["regime"]
        assert bool(rec["valid"]) == ev["valid"]
        for c, ok in ev["checks"].items():
            assert bool(rec[f"check_{c}"]) == ok


def test_sweep_modulus_and_all_models():
    arr = sweep({"modulus": [1e8, 2e8]}, model="all")
    assert arr.size == 6 and set(arr["model"]) == {"constant", "linear", "affine"}
    c = arr[arr["model"] == "constant"]
    assert c["theta"][0] / c["theta"][1] == pytest.approx(2.0)


def test_fit_power_law_synthetic():
    x = np.geomspace(1, 10, 20)
    f = fit_power_law(x, -3.5 * x ** 1.7)
    assert f["exponent"] == pytest.approx(1.7, abs=1e-12)
    assert f["prefactor"] == pytest.approx(3.5, rel=1e-12)
    assert f["r"] == pytest.approx(1.0, abs=1e-12)
    f = fit_power_law(x, x ** 2, mask=x < 5)
    assert f["n_left_out"] == int(np.sum(x >= 5))
    y = x ** 1.2 * (1 + 0.05 * np.sin(7 * x))
    assert fit_power_law(x, y)["r"] < 1.0


def test_small_displacement_exponents_exact_and_quarter_turn_left_out():
    arr = sweep({"length": np.linspace(0.01, 0.04, 16)}, model="affine")
    fits = {f["quantity"]: f for f in sweep_fits(arr, ["length"])}
    assert fits["w_small"]["exponent"] == pytest.approx(2.0, abs=1e-10)
    assert fits["F_block_small"]["exponent"] == pytest.approx(-1.0, abs=1e-10)
    assert fits["theta"]["exponent"] == pytest.approx(1.0, abs=1e-10)
    n_out = int(np.sum(np.abs(arr["theta"]) > np.pi / 2))
    assert n_out > 0 and fits["w"]["n_left_out"] == n_out
    assert 1.7 < fits["w"]["exponent"] < 2.0


def test_cli_sweep_json(capsys):
    import json

    from ipmc_asym.cli import main

    rc = main(["sweep", "--vary", "length=1cm:3cm:3", "--json", "--model", "linear"])
    assert rc == 0
    d = json.loads(capsys.readouterr().out)
    assert len(d["rows"]) == 3 and {"length", "I", "w", "F_block", "regime"} <= set(d["rows"][0])
    assert any(f["quantity"] == "w_small" for f in d["fits"])
    assert main(["sweep", "--vary", "bogus=1:2:3"]) == 2


def test_prefetched_keeps_order_raises_and_stops():
    """The background producer changes nothing but timing: same chunks in the same order, the
    producer's exception surfaces in the consumer, and a consumer that stops early stops it."""
    import threading

    from ipmc_asym.studies.sweeps import prefetched

    assert list(prefetched(iter(range(50)))) == list(range(50))

    def failing():
        yield 1
        raise ValueError("voltage must be finite (volts)")

    got = []
    with pytest.raises(ValueError, match="voltage"):
        for c in prefetched(failing()):
            got.append(c)
    assert got == [1]

    produced = []

    def endless():
        k = 0
        while True:
            produced.append(k)
            yield k
            k += 1

    g = prefetched(endless())
    assert next(g) == 0
    g.close()
    for t in threading.enumerate():
        if t.name == "ipmc-sweep-producer":
            t.join(timeout=5)
            assert not t.is_alive()
    assert len(produced) < 10


def test_prefetched_sweep_identical_to_serial():
    from ipmc_asym.studies.sweeps import prefetched

    vary = {"thickness": np.linspace(50e-6, 500e-6, 7), "voltage": np.linspace(-2.0, 3.0, 9)}
    a = np.concatenate(list(iter_sweep(vary, "all", "leading", chunk_rows=10)))
    b = np.concatenate(list(prefetched(iter_sweep(vary, "all", "leading", chunk_rows=10))))
    assert a.tobytes() == b.tobytes()


def test_spread_columns_are_the_range_of_the_three_models():
    """--spread: per row, min/max over the permittivity models of each model-dependent output,
    against one evaluate per model at that point (independent of the sweep's chunks)."""
    from ipmc_asym.studies.sweeps import SPREAD_COLS

    vary = {"length": [0.01, 0.03], "voltage": [0.5, 2.0]}
    arr = sweep(vary, model="linear", spread=True)
    plain = sweep(vary, model="linear")
    assert arr.size == 4 and set(SPREAD_COLS) <= set(arr.dtype.names)
    for c in plain.dtype.names:  # the row's own columns unchanged
        assert np.array_equal(arr[c], plain[c]) or np.array_equal(arr[c], plain[c], equal_nan=True)
    for rec in arr:
        s = Strip(length=float(rec["length"]), voltage=float(rec["voltage"]))
        for k in ("M_A", "theta", "w", "w_small", "F_block", "F_block_small"):
            got = [v for v in (evaluate(s, m, on_invalid="nan")[k] for m in ("constant", "linear", "affine"))
                   if v is not None]
            rel = 1e-10 if k == "F_block" else 1e-12
            assert rec[f"{k}_model_min"] == pytest.approx(min(got), rel=rel), k
            assert rec[f"{k}_model_max"] == pytest.approx(max(got), rel=rel), k
            assert rec[f"{k}_model_min"] <= rec[k] <= rec[f"{k}_model_max"] or not np.isfinite(rec[k])


def test_cli_sweep_spread_csv_and_refusal(capsys):
    from ipmc_asym.cli import main

    assert main(["sweep", "--vary", "length=1cm:3cm:3", "--spread", "--no-progress"]) == 0
    lines = [ln for ln in capsys.readouterr().out.splitlines() if not ln.startswith("#")]
    head = lines[0].split(",")
    assert head[-2:] == ["F_block_small_model_min", "F_block_small_model_max"] and len(lines) == 4
    row = dict(zip(head, lines[1].split(",")))
    assert float(row["w_model_min"]) <= float(row["w"]) <= float(row["w_model_max"])
    assert main(["sweep", "--vary", "length=1cm:3cm:3", "--spread", "--scheduler", "local"]) == 2
    assert "--spread" in capsys.readouterr().err


def test_two_points_make_no_test_of_a_power_law():
    """Through two points any exponent fits with |r| = 1: the fit says so instead of reading as a check."""
    f = fit_power_law([1.0, 2.0], [3.0, 7.0])
    assert f["n"] == 2 and f["exponent"] == pytest.approx(np.log(7 / 3) / np.log(2), rel=1e-12)
    assert "no test of a power law" in f["note"]
    assert "note" not in fit_power_law([1.0, 2.0, 4.0], [3.0, 7.0, 13.0])
