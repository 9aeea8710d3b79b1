"""``fit`` with electrode layers: E_m recovered from deflections made with a known E_m, and the
refusals of what deflection and force cannot identify (they see only the composite EI)."""

import numpy as np
import pytest

from ipmc_asym.forward.estimate import evaluate
from ipmc_asym.model.electrode import electrode_from_spec
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.studies.calibrate import check_stiffness_free, fit, read_data


def _layered(t, Em=None):
    spec = {"thickness": t, "metal": "platinum"}
    if Em is not None:
        spec["modulus"] = Em
    return NAFION_LI.with_(electrode=electrode_from_spec(spec))


def test_refusals():
    with pytest.raises(ValueError, match="no electrode layer"):
        check_stiffness_free(["electrode_modulus"], NAFION_LI)
    with pytest.raises(ValueError, match="only through the bending stiffness"):
        check_stiffness_free(["modulus", "electrode_thickness"], _layered(1e-6))
    check_stiffness_free(["electrode_modulus", "c_moy"], _layered(1e-6))  # identifiable: no error


def test_fit_recovers_the_layer_modulus(tmp_path):
    true = _layered(1e-6, 20e9)
    rng = np.random.default_rng(3)
    lines = ["voltage,deflection,sigma_deflection"]
    for v in np.linspace(0.3, 1.0, 6):
        w = abs(evaluate(Strip(voltage=float(v)), "constant", "quadrature", true)["w"])
        lines.append(f"{v:.4f}V,{w * (1 + 0.01 * rng.standard_normal()) * 1e3:.10g}mm,{0.01 * w:.6g}")
    p = tmp_path / "d.csv"
    p.write_text("\n".join(lines) + "\n")
    res = fit(read_data(str(p)), "electrode_modulus", material=_layered(1e-6))
    par = res.parameters["electrode_modulus"]
    assert par["identifiable"] and par["value"] == pytest.approx(20e9, rel=0.03)
    lo, hi = par["ci95"]
    assert lo < 20e9 < hi
