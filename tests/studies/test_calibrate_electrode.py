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


def _three_layer_EI(Ep, Em, tm, width=5e-3, h=200e-6):
    """Symmetric three-layer section written out here: membrane 2e = h, two layers t_m (each face)."""
    return Ep * width * h**3 / 12 + Em * width * ((h + 2 * tm) ** 3 - h**3) / 12


def test_static_data_identify_the_composite_stiffness(tmp_path):
    """Deflections made with t_m = 2 um: freeing t_m from a 1 um start recovers it, and the fitted
    layer gives the composite EI of the true section (the one number the data see)."""
    true = _layered(2e-6, 20e9)
    rng = np.random.default_rng(5)
    lines = ["voltage,deflection,sigma_deflection"]
    for v in np.linspace(0.3, 1.0, 6):
        w = abs(evaluate(Strip(voltage=float(v)), "constant", "quadrature", true)["w"])
        lines.append(f"{v:.4f}V,{w * (1 + 0.005 * rng.standard_normal()) * 1e3:.10g}mm,{0.005 * w:.6g}")
    p = tmp_path / "d.csv"
    p.write_text("\n".join(lines) + "\n")
    res = fit(read_data(str(p)), "electrode_thickness", material=_layered(1e-6, 20e9))
    par = res.parameters["electrode_thickness"]
    t = par["value"]
    assert par["identifiable"] and t == pytest.approx(2e-6, rel=0.03)
    assert par["ci95"][0] < 2e-6 < par["ci95"][1]
    EI_true = _three_layer_EI(NAFION_LI.E, 20e9, 2e-6)
    assert _three_layer_EI(NAFION_LI.E, 20e9, t) == pytest.approx(EI_true, rel=0.03)


@pytest.mark.parametrize("free", ["electrode_thickness", "electrode_modulus"])
def test_impedance_and_current_data_see_no_layer(tmp_path, free):
    """The layers change the beam, not the electrochemistry: a spectrum, or a current transient,
    cannot identify t_m or E_m, and the fit says which data would (one line)."""
    from ipmc_asym.studies.calibrate_dynamic import fit_dynamic, read_file

    imp = tmp_path / "imp.csv"
    imp.write_text("f,Z_re,Z_im\n1Hz,10,-5\n10Hz,8,-2\n100Hz,7,-1\n")
    cur = tmp_path / "cur.csv"
    cur.write_text("t,voltage,current\n1ms,1V,1mA\n2ms,1V,0.8mA\n3ms,1V,0.7mA\n")
    for path in (imp, cur):
        with pytest.raises(ValueError, match=f"{free}: the data given .* deflection or blocking-force") as e:
            fit_dynamic(read_file(path), free, material=_layered(1e-6))
        assert "\n" not in str(e.value)
