"""One answer for one point: ``ia.sweep`` withholds what ``ia.evaluate`` withholds (NaN in the
array where the row has None), and gives the same numbers elsewhere; a scene withholds one
output at one point instead of refusing the whole scene."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ipmc_asym as ia
from ipmc_asym.studies.scenes import run_scene

KEYS = ("I", "M_A", "theta", "w", "w_small", "F_block", "F_block_small")


def _strips(n=40, seed=7):
    # log-uniform over lengths, thicknesses and voltages that reach past a full turn
    rng = np.random.default_rng(seed)
    L = 10 ** rng.uniform(-2.3, -0.7, n)
    th = 10 ** rng.uniform(-5, -3.3, n)
    v = rng.uniform(0.2, 5.0, n)
    return L, th, v


def test_sweep_withholds_like_evaluate():
    L, th, v = _strips()
    n_withheld = 0
    for i in range(L.size):
        row = ia.evaluate(ia.Strip(length=L[i], thickness=th[i], voltage=v[i]), on_invalid="nan")
        arr = ia.sweep({"length": np.array([L[i]]), "thickness": np.array([th[i]]), "voltage": np.array([v[i]])})
        for k in KEYS:
            a = float(arr[k][0])
            if row[k] is None:
                n_withheld += 1
                assert math.isnan(a), (i, k, a)
            else:
                assert a == pytest.approx(row[k], rel=1e-12, abs=0.0), (i, k)
    assert n_withheld > 0  # the draw reaches past a full turn


def test_scene_withholds_one_blocking_force(tmp_path):
    """A scene whose last voltage bends the strip past the tracked blocking-force branch: that
    point's F_block is None with a warning, the others are evaluate's."""
    strip = ia.Strip(length=0.2, thickness=20e-6, voltage=1.0)
    volts = [0.01, 20.0]
    rows = [ia.evaluate(ia.Strip(length=strip.length, thickness=strip.thickness, voltage=u), on_invalid="nan")
            for u in volts]
    assert rows[0]["F_block"] is not None and rows[1]["F_block"] is None  # the reference itself
    scene = {"name": "s", "outputs": ["blocking_force", "tip_deflection"], "voltages": [f"{u}V" for u in volts],
             "strip": {"length": "20cm", "thickness": "20um"}, "tolerance": 1e-3}
    res = run_scene(scene)
    F = res["outputs"]["blocking_force"]["values"]
    assert F[1] is None and F[0] == pytest.approx(rows[0]["F_block_small"] if res["outputs"]["blocking_force"]
                                                  ["beam"][0] == "small" else rows[0]["F_block"], rel=2e-3)
    assert any("blocking_force withheld" in w for w in res["warnings"])
