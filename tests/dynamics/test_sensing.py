"""Sensing in the frequency domain: the closed form against a numerical solve of the linearised
PNP with the bending source, its static limit against ``ia.sense``, the actuation's impedance,
the matched load, reciprocity at low frequency, the circuit's stated error, refusals."""

import math

import numpy as np
import pytest

import ipmc_asym as ia
from ipmc_asym.dynamics.sensing import sensing_response, voc_hat, voc_hat_leading
from ipmc_asym.kernels import _generated_charge as GC
from ipmc_asym.model import groups

MAT = ia.NAFION_LI


def _cheb(n):
    """Chebyshev points on [-1, 1] and the differentiation matrix (Trefethen, Spectral Methods in MATLAB)."""
    x = np.cos(np.pi * np.arange(n + 1) / n)
    c = np.hstack([2.0, np.ones(n - 1), 2.0]) * (-1.0) ** np.arange(n + 1)
    X = np.tile(x, (n + 1, 1)).T
    D = np.outer(c, 1 / c) / (X - X.T + np.eye(n + 1))
    return x, D - np.diag(D.sum(axis=1))


def _numeric(W, lam, load, n=80):
    """``sigma/S`` (short) or ``V_oc F/RT`` (open) per unit b by Chebyshev collocation of the linearised PNP.

    The equations of derivations/sensing_dynamic.py written out independently: ``s c = mu''``
    (Nernst-Planck, blocking faces ``mu'(+-1) = 0``), ``lam^2 psi'' = -(c - zeta)`` (Gauss with the
    fixed-charge source), ``psi = mu - c``, so ``c'' = s c + (c - zeta)/lam^2``; short circuit
    ``psi(-1) = psi(1)``, open ``psi'(-1) = 0`` (no face charge); gauge ``mu(-1) + mu(1) = 0``.
    """
    s = 1j * W
    x, D = _cheb(n)
    D2 = D @ D
    m = n + 1
    I = np.eye(m)
    A = np.zeros((2 * m, 2 * m), dtype=complex)
    rhs = np.zeros(2 * m, dtype=complex)
    A[:m, :m] = D2 - (s + 1 / lam**2) * I  # c'' - k^2 c = -zeta/lam^2
    rhs[:m] = -x / lam**2
    A[m:, :m] = -s * I  # mu'' - s c = 0
    A[m:, m:] = D2
    # boundary rows replace the equations at the end points (x[0] = 1, x[n] = -1)
    top, bot = 0, n
    A[top] = 0
    A[top, m:] = D[top]  # mu'(1) = 0
    rhs[top] = 0
    A[bot] = 0
    A[bot, m:] = D[bot]  # mu'(-1) = 0
    rhs[bot] = 0
    A[m + top] = 0
    A[m + bot] = 0
    rhs[m + top] = rhs[m + bot] = 0
    if load == "short":  # psi(-1) - psi(1) = 0
        A[m + top, m + bot], A[m + top, bot], A[m + top, m + top], A[m + top, top] = 1, -1, -1, 1
    else:  # psi'(-1) = mu'(-1) - c'(-1) = 0
        A[m + top, m:] = D[bot]
        A[m + top, :m] = -D[bot]
    A[m + bot, m + top] = A[m + bot, m + bot] = 1  # gauge
    y = np.linalg.solve(A, rhs)
    c, mu = y[:m], y[m:]
    psi = mu - c
    if load == "short":
        return -lam * (D[bot] @ psi)
    return psi[bot] - psi[top]


def _admittance(W, lam):
    """``sigma/(S v)`` of the actuation's impedance (``derivations/charge.py``): ``1/(i W lam Zhat)``."""
    return 1.0 / (1j * W * lam * GC.impedance_hat(np.array([W]), lam)[0])


@pytest.mark.parametrize("lam", (0.05, 0.2))
@pytest.mark.parametrize("W", (0.5, 20.0, 300.0))
def test_closed_form_against_a_numerical_solve(lam, W):
    v = complex(voc_hat(np.array([W]), lam)[0])
    assert abs(_numeric(W, lam, "open") - v) <= 1e-7 * abs(v)
    # short circuit: the Thevenin pair with the ACTUATION's admittance, sigma = -Y v_oc
    sig = -_admittance(W, lam) * v
    assert abs(_numeric(W, lam, "short") - sig) <= 1e-7 * abs(sig)


def test_leading_order_is_the_static_emf_plus_the_streaming_potential():
    lam = 1e-4
    W = np.array([1e-3, 0.3, 30.0, 3000.0])
    v = voc_hat(W, lam)
    lead = voc_hat_leading(W, lam)
    # the remainder is O(lam^2 (1 + W)^2): measured (2/3) (W lam)^2 at large W (the dielectric relaxation)
    assert np.all(np.abs(v - lead) <= lam**2 * (1 + W) ** 2)
    # the streaming potential: Im v = 2W/3; the static EMF would be 2 (1 - lam)
    assert np.allclose(v.imag, 2 * W / 3, rtol=1e-3)
    assert voc_hat(np.array([0.0]), 0.3)[0] == pytest.approx(2 * (1 - 0.3 * math.tanh(1 / 0.3)), rel=1e-13)


@pytest.mark.parametrize("model", ("constant", "linear", "affine"))
@pytest.mark.parametrize("support", ("free", "tip-force"))
@pytest.mark.parametrize("nu", (0.0, 0.3))
def test_low_frequency_limit_is_the_static_sense(model, support, nu):
    f = 1e-9  # W = 2 pi f e^2/D = 6e-7: the streaming part is W/3 = 2e-7 of the static EMF
    r = sensing_response([f], model=model, support=support, nu=nu)
    st = ia.sense(tip_displacement=[1e-3], support=support, model=model, nu=nu, fidelity="leading")
    W = 2 * math.pi * f * (100e-6) ** 2 / MAT.D
    tol = W + 1e-9  # + the layers' 2 pi f tau
    assert abs(r.Q_per_w[0] - st.Q_per_w[0]) <= tol * abs(st.Q_per_w[0]) + 2 * math.pi * f * r.tau * abs(st.Q_per_w[0])
    assert abs(r.V_oc_per_w[0] - st.V_oc[0] / 1e-3) <= tol * abs(st.V_oc[0] / 1e-3)


def test_short_circuit_current_and_open_voltage_are_one_thevenin_pair():
    f = np.geomspace(1e-4, 1e3, 15)
    r = sensing_response(f, model="linear")
    fr = ia.frequency_response(f, model="linear")
    assert np.allclose(r.Z, fr.Z, rtol=0, atol=0)
    # I_sc = -V_oc/Z, the current onto the electrode z = -e
    assert np.allclose(r.I_per_w, -r.V_oc_per_w / r.Z, rtol=1e-12)
    assert np.allclose(r.I_per_w, 2j * np.pi * f * r.Q_per_w, rtol=1e-14)


@pytest.mark.parametrize("f", (1e-3, 0.5, 22.5))
def test_power_peaks_at_the_matched_resistance(f):
    r = sensing_response([f], model="constant", load=1.0)
    Zm = abs(r.Z[0])
    R = Zm * np.geomspace(0.2, 5.0, 4001)
    P = r.power_at(R)[0]
    j = int(np.argmax(P))
    assert R[j] == pytest.approx(Zm, rel=2e-3)
    # the maximum: |V_oc|^2/(4 (|Z| + Re Z)) at R = |Z|
    voc = abs(r.V_oc_per_w[0]) * r.amplitude
    best = sensing_response([f], model="constant", load=Zm)
    assert best.power[0] == pytest.approx(voc**2 / (4 * (Zm + r.Z[0].real)), rel=1e-12)
    assert best.power[0] >= P.max() * (1 - 1e-12)
    # the load columns: V_load = V_oc R/(R + Z), I_load = V_load/R
    assert best.V_load[0] == pytest.approx(r.V_oc_per_w[0] * r.amplitude * Zm / (Zm + r.Z[0]), rel=1e-12)
    assert best.I_load[0] == pytest.approx(best.V_load[0] / Zm, rel=1e-14)


@pytest.mark.parametrize("model", ("constant", "linear"))
@pytest.mark.parametrize("nu", (0.0, 0.3))
def test_reciprocity_ratio_persists_at_low_frequency(model, nu):
    # sensing Q/w (tip force) against the actuation's blocked force per volt, both at 1e-8 Hz
    f = [1e-8]
    q = sensing_response(f, model=model, nu=nu).Q_per_w[0]
    hf = ia.frequency_response(f, model=model).H_F[0]
    pred = (1 - 2 * nu) / (3 * (1 + float(groups.A3(MAT))))
    # the strip's force on the blocker along w is -H_F per volt (docs/sensing.md)
    assert (q / -hf).real == pytest.approx(pred, rel=1e-5)
    # ... and does not persist at higher frequency: the sensing side has the streaming term
    q1 = sensing_response([1.0], model=model, nu=nu).Q_per_w[0]
    h1 = ia.frequency_response([1.0], model=model).H_F[0]
    assert abs(q1 / -h1) > 2 * pred


def test_circuit_error_covers_its_departure_from_the_exact_form():
    f = np.geomspace(1e-4, 1e5, 25)
    for model in ("constant", "affine"):
        for th in (20e-6, 200e-6, 1e-3):
            s = ia.Strip(thickness=th)
            ex = sensing_response(f, s, model=model)
            ci = sensing_response(f, s, model=model, method="circuit")
            for a, b in ((ci.Q_per_w, ex.Q_per_w), (ci.V_oc_per_w, ex.V_oc_per_w)):
                assert np.all(np.abs(a / b - 1) <= ci.error)
            assert np.all(ex.error == 0)


def test_flags_and_notes():
    r = sensing_response([1e-4, 1.0], model="constant")
    assert r.check_one_way.tolist() == [True, False] and r.valid.tolist() == [True, False]
    assert any("water instantly redistributed" in n for n in r.notes)
    assert r.f_stream == pytest.approx(3 * MAT.D / (2 * math.pi * (100e-6) ** 2))
    big = sensing_response([1e-4], amplitude=2e-2)  # 2 cm tip displacement of a 2 cm strip: past the checks
    assert not big.check_beam_regime and not big.valid[0]
    ds = r.to_xarray()
    assert ds["Q_per_w"].attrs["units"] == "C/m"


@pytest.mark.parametrize("kw, word", [
    ({"load": "resistive"}, "load"), ({"load": -5.0}, "load"), ({"load": True}, "load"),
    ({"amplitude": 0.0}, "amplitude"), ({"amplitude": float("nan")}, "amplitude"), ({"nu": 0.6}, "nu"),
    ({"support": "clamped-free"}, "support"), ({"method": "bvp"}, "method"), ({"amplitude": 1.0}, "amplitude"),
])
def test_refusals_name_the_input(kw, word):
    with pytest.raises(ValueError, match=word):
        sensing_response([1.0], **kw)
    with pytest.raises(ValueError, match="frequencies"):
        sensing_response([0.0])


def test_summary_plot_and_dataset():
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    r = sensing_response(np.geomspace(1e-4, 1.0, 7), model="affine", load=1e3)
    text = repr(r)
    assert text.startswith("SensingResponse") and "[C/m]" in text and "[W]" in text
    fig = r.plot()
    assert isinstance(fig, Figure) and all(ax.get_ylabel() for ax in fig.axes)
    ds = r.to_xarray()
    assert ds["harvested_power"].attrs["units"] == "W" and ds.attrs["load_resistance"] == 1e3
