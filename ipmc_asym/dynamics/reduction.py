"""Reduced-order models for control: a rational fit of a transfer function over a band.

:func:`transfer_function` samples :func:`ipmc_asym.dynamics.circuit.frequency_response`
(the full model: the exact linearised Nernst-Planck/Gauss solution by default) over a
frequency band and fits it by vector fitting (:func:`vector_fit`) on the samples at
``+i omega`` and their conjugates at ``-i omega``, so that the fit is real (real poles and
conjugate pairs), stable (an unstable pole is reflected into the left half-plane), with the
order raised step by step until the tolerance is met; the result is a pole-residue model
``H(s) = d + sum_k r_k/(s - p_k)`` with a real state-space realisation.  Its error is
stated: the largest relative deviation from the full model of either form (the pole-residue sum
and the state space) on a check grid four times denser than the fit grid, at the fit's own
resonances and zoomed around the grid's maxima, over the band.  An undamped dynamic beam's
resonances and antiresonances lie on the imaginary axis: they are restored exactly (the fit is of
the smooth remainder).  Outside the band nothing is claimed.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field

import numpy as np

from ipmc_asym.base.inputs import read_input_text
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.beam.dynamics import DEFAULT_MODES, natural_frequencies, transfer
from ipmc_asym.dynamics.circuit import frequency_response, strip_beam
from ipmc_asym.dynamics.line import line_response
from ipmc_asym.model.params import NAFION_LI, Material, Strip

__all__ = ["RationalModel", "ExportedModels", "load_export", "transfer_function", "vector_fit", "OUTPUTS", "MAX_ORDER"]

#: the transfer functions :func:`transfer_function` exports: name -> (meaning, unit)
OUTPUTS = {"w": ("tip deflection per volt (small displacements)", "m/V"),
           "charge": ("electrode charge per volt, electrode area 2l L", "C/V"),
           "current": ("current per volt, electrode area 2l L (admittance; improper: s x charge)", "A/V"),
           "impedance": ("impedance, electrode area 2l L", "Ohm")}
#: largest model order (number of poles) a fit may use, and the orders tried in turn
MAX_ORDER = 60
ORDERS = (2, 4, 6, 8, 12, 16, 20, 24, 32, 40, 48, 60)


@dataclass(repr=False)
class RationalModel(ResultMixin):
    """``H(s) = d1 s + d + sum_k residues[k]/(s - poles[k])``, ``s = 2 pi i f`` (rad/s).

    Attributes
    ----------
    poles, residues : ndarray of complex, shape (n,)   real poles (imaginary part exactly 0) and
        exact conjugate pairs, Re(poles) <= 0 (0: an integrator, the impedance's capacitor)
    d : float   direct term
    d1 : float  coefficient of ``s`` (nonzero only for the current: the bulk's geometric
        capacitance passes ``C_g dV/dt``, an improper transfer; no state space exists for it)
    band : (float, float)   the band of the fit (Hz); the stated error holds there only
    max_rel_error : float   largest ``|H_fit - H| / |H|`` of the pole-residue and the state-space
        forms in the band (check grid, the fit's resonances, zoomed around the maxima)
    output : str ; unit : str ; model : str ; method : str   what was fitted
    success : bool   the fit met ``tol`` on the check grid
    message : str
    """

    _result = ResultSpec("f", None, ())
    #: vocabulary name of each exported output's transfer function
    _H_NAMES = {"w": "H_w", "charge": "H_charge", "current": "H_current", "impedance": "Z"}

    def _arrays(self):
        f = np.geomspace(*self.band, 200) if self.band[0] > 0 else np.linspace(*self.band, 200)
        return "f", f, {self._H_NAMES[self.output]: self(f)}

    def _panels(self, arrays):
        return (Panel("f", tuple(arrays), True, True),)

    poles: np.ndarray
    residues: np.ndarray
    d: float
    band: tuple
    max_rel_error: float
    output: str
    unit: str
    model: str
    method: str
    success: bool
    message: str
    notes: list = field(default_factory=list)
    d1: float = 0.0

    @property
    def order(self) -> int:
        return int(self.poles.size)

    def __call__(self, f):
        """The fitted response at frequencies ``f`` (Hz), complex, shape of ``f``."""
        s = 2j * math.pi * np.asarray(f, dtype=float)
        return self.d1 * s + self.d + np.sum(self.residues / (s[..., None] - self.poles), axis=-1)

    def state_space(self):
        """Real ``(A, B, C, D)`` with ``H(s) = C (sI - A)^{-1} B + D``: one state per real pole,
        a 2x2 block ``[[a, b], [-b, a]]`` per conjugate pair ``a +- ib``."""
        if self.d1 != 0.0:
            raise ValueError(f"output {self.output!r} is improper (d1 s term): no state space; "
                             "export output='charge' and differentiate (current = s x charge)")
        A, B, C = [], [], []
        for p, r in zip(self.poles, self.residues):
            if p.imag == 0.0:
                A.append(np.array([[p.real]]))
                B.append(np.array([1.0]))
                C.append(np.array([r.real]))
            elif p.imag > 0.0:
                # r/(s - p) + conj(r)/(s - conj p) = C (sI - A)^{-1} B with A = [[a, b], [-b, a]]
                A.append(np.array([[p.real, p.imag], [-p.imag, p.real]]))
                B.append(np.array([0.0, 2.0]))
                C.append(np.array([-r.imag, r.real]))
        n = sum(a.shape[0] for a in A)
        Am = np.zeros((n, n))
        i = 0
        for a in A:
            m = a.shape[0]
            Am[i:i + m, i:i + m] = a
            i += m
        return Am, np.concatenate(B)[:, None], np.concatenate(C)[None, :], np.array([[self.d]])

    def to_control(self, form="ss"):
        """The model for the optional python-control package.

        Parameters
        ----------
        form : {"ss", "tf"}
            ``"ss"``: a ``control.StateSpace`` (the real realisation of :meth:`state_space`);
            ``"tf"``: a ``control.TransferFunction`` (numerator/denominator polynomials in ``s``,
            rad/s; of an order-n model a ratio of degree-n polynomials, ill-conditioned past
            order ~20: prefer ``"ss"`` there).
        """
        if form not in ("ss", "tf"):
            raise ValueError(f"form must be 'ss' or 'tf'; got {form!r}")
        try:
            import control  # deferred: optional dependency (pip install ".[control]")
        except ImportError:
            raise ValueError("to_control needs the python-control package: pip install \"ipmc_asym[control]\"") from None
        sys_ = control.ss(*self.state_space())
        return sys_ if form == "ss" else control.ss2tf(sys_)

    @classmethod
    def from_dict(cls, d: dict, where: str = "model") -> RationalModel:
        """The model of :meth:`to_dict` (a ``freq --export`` file's ``models[output]``).

        Raises
        ------
        ValueError
            One line naming the missing or malformed key.
        """
        def get(k):
            if not isinstance(d, dict) or k not in d:
                raise ValueError(f"{where}: no key {k!r} (a model written by freq --export / RationalModel.to_dict)")
            return d[k]

        def pairs(k):
            v = get(k)
            try:
                a = np.asarray(v, dtype=float).reshape(-1, 2)
            except (TypeError, ValueError):
                raise ValueError(f"{where}: {k!r} must be a list of [re, im] pairs") from None
            if not np.all(np.isfinite(a)):
                raise ValueError(f"{where}: {k!r} must be finite")
            return a[:, 0] + 1j * a[:, 1]

        poles, residues = pairs("poles"), pairs("residues")
        if poles.size != residues.size:
            raise ValueError(f"{where}: {poles.size} poles but {residues.size} residues")
        output = get("output")
        if output not in OUTPUTS:
            raise ValueError(f"{where}: output must be one of {', '.join(OUTPUTS)}; got {output!r}")
        try:
            band = tuple(float(x) for x in get("band_Hz"))
            num = {k: float(get(k)) for k in ("d", "d1", "max_rel_error")}
        except (TypeError, ValueError):
            raise ValueError(f"{where}: band_Hz, d, d1 and max_rel_error must be numbers") from None
        return cls(poles=poles, residues=residues, d=num["d"], band=band, max_rel_error=num["max_rel_error"],
                   output=output, unit=str(get("unit")), model=str(get("model")), method=str(get("method")),
                   success=bool(get("success")), message=str(get("message")), notes=list(d.get("notes", [])),
                   d1=num["d1"])

    def to_dict(self) -> dict:
        """JSON-ready: poles and residues as [re, im] pairs, the state space, the stated error."""
        ss = None if self.d1 != 0.0 else dict(zip("ABCD", (x.tolist() for x in self.state_space())))
        return {"output": self.output, "unit": self.unit, "model": self.model, "method": self.method,
                "s": "2 pi i f (rad/s)", "form": "H(s) = d1 s + d + sum_k r_k / (s - p_k) = C (sI - A)^-1 B + D (when d1 = 0)",
                "band_Hz": list(self.band), "order": self.order, "max_rel_error": self.max_rel_error,
                "success": self.success, "message": self.message,
                "poles": [[p.real, p.imag] for p in self.poles],
                "residues": [[r.real, r.imag] for r in self.residues], "d": self.d, "d1": self.d1,
                "state_space": ss,
                "notes": list(self.notes)}


def _symmetric(poles):
    """Stable, conjugate-symmetric pole set: unstable poles reflected into the left half-plane (as
    vector fitting does), poles near the real axis made real (coincident ones merged), each upper
    pole paired with its conjugate."""
    poles = np.where(poles.real > 0, -poles.conj(), poles)
    # a pair within 1e-3 of the real axis is a real double pole (no oscillation at a quality
    # factor < 5e-4): as a pair it fits with huge opposite residues that cancel (rounding)
    small = np.abs(poles.imag) <= 1e-3 * np.abs(poles)
    upper = poles[~small & (poles.imag > 0)]
    real = np.sort(poles[small].real)
    keep = np.concatenate([[True], np.diff(real) > 1e-6 * np.abs(real[1:])]) if real.size else np.zeros(0, bool)
    return np.concatenate([real[keep].astype(complex), upper, upper.conj()])


def vector_fit(s, H, order, iterations=12, proper=True):
    """Vector fitting (Gustavsen & Semlyen, IEEE Trans. Power Delivery 14 (1999) 1052) of the
    samples ``H`` at the points ``s`` (conjugate-symmetric: both ``s`` and ``conj(s)``), in
    RELATIVE error (rows weighted by ``1/|H|``: a transfer function spans decades).

    Starting poles: lightly damped pairs ``-b/100 +- i b``, ``b`` log-spaced over ``|s|``; each
    iteration solves ``sigma H = p`` by linear least squares and moves the poles to the zeros of
    ``sigma``.  Returns the poles, residues and the direct term of ``d + sum r/(s - p)``
    (``proper=False``: strictly proper, ``d = 0``).
    """
    s = np.asarray(s, complex)
    H = np.asarray(H, complex)
    w = 1.0 / np.abs(H)
    a = np.abs(s[np.abs(s) > 0])
    b = np.geomspace(a.min(), a.max(), max(1, order // 2))
    poles = np.concatenate([-b / 100 + 1j * b, -b / 100 - 1j * b])
    if order % 2:
        poles = np.append(poles, -np.sqrt(a.min() * a.max()) + 0j)
    for _ in range(iterations):
        n = poles.size
        Phi = 1.0 / (s[:, None] - poles[None, :])
        M = np.hstack([Phi, np.ones((s.size, 1)), -H[:, None] * Phi]) * w[:, None]
        x, *_ = np.linalg.lstsq(M, H * w, rcond=None)
        poles = _symmetric(np.linalg.eigvals(np.diag(poles) - np.outer(np.ones(n), x[n + 1:])))
    return _residues(s, H, w, poles, proper)


def _residues(s, H, w, poles, proper):
    """``(poles, residues, d)`` of the weighted least-squares fit with the poles fixed: the poles as
    real ones, upper ones, their conjugates in the same order (``_symmetric``'s layout), the residues
    conjugate-symmetric (real at a real pole, ``r`` and ``conj(r)`` at a pair), ``d`` real.

    Solved for real unknowns (a real pole's residue; ``Re r`` and ``Im r`` of a pair: ``r/(s - p) +
    conj(r)/(s - conj p) = Re r (1/(s - p) + 1/(s - conj p)) + Im r (i/(s - p) - i/(s - conj p))``)
    from the real and imaginary parts of the rows.  The complex least squares has the same
    conjugate-symmetric solution in exact arithmetic only: with two nearly coincident poles its
    columns are nearly dependent and the rounding left the two residues of a pair apart (5.6e-6
    relative, measured on the impedance fit at 1e-2-1e3 Hz, constant model), an amount that
    differs from one LAPACK to another -- and the state space, built from the upper residue alone,
    then differed from the pole-residue sum by as much.
    """
    real = poles.imag == 0.0
    pr, up = poles[real], poles[poles.imag > 0.0]

    def inv(p):
        return 1.0 / (s[:, None] - p[None, :])

    cols = [inv(pr), inv(up) + inv(up.conj()), 1j * (inv(up) - inv(up.conj()))]
    if proper:
        cols.append(np.ones((s.size, 1)))
    M = np.hstack(cols) * w[:, None]
    y = H * w
    x, *_ = np.linalg.lstsq(np.vstack([M.real, M.imag]), np.concatenate([y.real, y.imag]), rcond=None)
    nr, nu = pr.size, up.size
    ru = x[nr:nr + nu] + 1j * x[nr + nu:nr + 2 * nu]
    return (np.concatenate([pr, up, up.conj()]), np.concatenate([x[:nr], ru, ru.conj()]),
            float(x[-1]) if proper else 0.0)


def _forms_error(fit, f, H):
    """Relative error ``|H_form - H|/|H|`` at ``f`` (Hz) of the worse of the two forms a user receives:
    the pole-residue sum and, for a proper model, the state space ``C (sI - A)^{-1} B + D`` evaluated
    by a dense solve (as a control toolbox would; its rounding differs from the sum's where poles
    nearly cancel).

    Plus a bound on the rounding of either evaluation, ``4 (n + 2) eps sum_k |r_k/(s - p_k)| / |H|``
    (``n`` terms and the direct ones, each rounded: the sum's error is at most ``(n + 1) eps`` times
    the sum of the terms' sizes; the block-diagonal solve rounds each 2x2 block alike): what is
    measured here is this machine's rounding, and another BLAS or CPU evaluates the same model with
    a different one, within this bound of the exact value.
    """
    s = 2j * math.pi * np.asarray(f, dtype=float)
    terms = np.sum(np.abs(fit.residues / (s[:, None] - fit.poles[None, :])), axis=1) + abs(fit.d) + np.abs(fit.d1 * s)
    rounding = 4.0 * (fit.order + 2) * np.finfo(float).eps * terms / np.abs(H)
    err = np.abs(fit(f) - H) / np.abs(H)
    if fit.d1 == 0.0 and fit.order:
        A, B, C, D = fit.state_space()
        M = s[:, None, None] * np.eye(A.shape[0])[None] - A[None]
        x = np.linalg.solve(M, np.broadcast_to(B.astype(complex), (s.size,) + B.shape))
        ss = (C[None] @ x)[:, 0, 0] + D[0, 0]
        err = np.maximum(err, np.abs(ss - H) / np.abs(H))
    return err + rounding


def _stated_error(fit, full, f_chk, Hc, output, w0, levels=2, sub=8, peaks=40):
    """The largest relative error of the exported forms over the band: on the check grid, then zoomed
    around its local maxima (``levels`` times, ``sub`` log-spaced points between the neighbours of each
    of the ``peaks`` largest): between two check points the error can rise above both (near a lightly
    damped or undamped mode, where ``H`` varies faster than the grid)."""
    err = _forms_error(fit, f_chk, Hc)
    f, e = f_chk, err
    lo_b, hi_b = f_chk[0], f_chk[-1]
    # the fit's own resonances in the band: there the fit peaks (|H_fit| ~ |r/Re p|), and with a
    # lightly damped or undamped full model the two peaks need not coincide -- the relative error
    # there is the one the check grid misses
    fp = np.abs(fit.poles.imag) / (2.0 * math.pi)
    # (poles exactly on the axis are the full model's own undamped resonances, placed exactly: no peak
    # of its own, the error near them is the smooth factor's)
    fp = np.unique(fp[(fp > lo_b) & (fp < hi_b) & (fit.poles.imag != 0.0) & (fit.poles.real != 0.0)])
    if fp.size:
        Hp, _ = full(fp)
        if output == "current":
            Hp = Hp * 2j * math.pi * fp
        with np.errstate(divide="ignore", invalid="ignore"):
            ep = np.nan_to_num(_forms_error(fit, fp, Hp), nan=np.inf)
        o = np.argsort(np.concatenate((f, fp)))
        f, e = np.concatenate((f, fp))[o], np.concatenate((e, ep))[o]
    worst = float(np.max(e))
    for _ in range(levels):
        inner = (e[1:-1] >= e[:-2]) & (e[1:-1] >= e[2:])
        idx = np.concatenate(([0] if e[0] >= e[1] else [], 1 + np.nonzero(inner)[0],
                              [e.size - 1] if e[-1] >= e[-2] else [])).astype(int)
        idx = idx[np.argsort(e[idx])[::-1][:peaks]]
        if idx.size == 0:
            break
        fz = np.unique(np.concatenate([np.geomspace(f[max(i - 1, 0)], f[min(i + 1, f.size - 1)], sub + 2)
                                       for i in idx]))
        fz = fz[(fz >= lo_b) & (fz <= hi_b)]
        Hz, _ = full(fz)
        if output == "current":
            Hz = Hz * 2j * math.pi * fz
        ez = _forms_error(fit, fz, Hz)
        worst = max(worst, float(np.max(ez)))
        f, e = fz, ez
    # each maximum is located to 1/(sub + 1)^levels of a check interval, where the error is smooth
    # (quadratic about its maximum): 1 % covers what lies between the last samples
    return 1.01 * worst


def transfer_function(f_min, f_max, *, strip: Strip | None = None, model="constant", material: Material | None = None,
                      output="w", method="pnp-linear", tol=1e-4, points=200, **response_kw) -> RationalModel:
    """A reduced-order rational model of ``output`` over the band ``[f_min, f_max]`` (Hz).

    Parameters
    ----------
    f_min, f_max : float
        The band (Hz), ``0 < f_min < f_max``.
    strip : Strip, optional ; model : str ; material : Material, optional
    output : {"w", "charge", "current", "impedance"}
        ``w``: tip deflection per volt (m/V); ``charge``: electrode charge per volt (C/V,
        electrode area 2l L); ``current``: ``s`` x charge (A/V; improper, no state space);
        ``impedance``: Z (Ohm).  See :data:`OUTPUTS`.
    method : {"pnp-linear", "circuit"}
        The full model sampled (:func:`ipmc_asym.dynamics.circuit.frequency_response`).
    tol : float
        Relative error aimed at on the band, in (0, 1).
    points : int
        Log-spaced fit frequencies (the check grid has four times as many), 20-5000.
    **response_kw
        Passed to :func:`~ipmc_asym.dynamics.circuit.frequency_response` (``beam="dynamic"``,
        ``viscous_modulus``, ``voltage``): the fit is of that response.  With ``sheet_resistance``
        (Ohm/sq) the full model is the electrode line :func:`ipmc_asym.dynamics.line.line_response`
        (``Z = Z_u g coth g`` is not rational: the order rises until the band meets ``tol``, and the
        error on the check grid is stated as for the uniform strip).  An undamped dynamic
        beam (``viscous_modulus`` 0) has its resonances and antiresonances on the imaginary axis:
        they are placed exactly (the modes' natural frequencies, the tip response's real zeros).

    Returns
    -------
    RationalModel
        ``success`` is False (with a message) when the fit misses ``tol`` on the check grid;
        ``max_rel_error`` is the error measured there either way.

    Examples
    --------
    >>> import ipmc_asym as ia
    >>> tf = ia.transfer_function(0.01, 1000.0, model="constant")
    >>> tf.success and tf.max_rel_error < 1e-4
    True
    >>> A, B, C, D = tf.state_space()
    """
    if output not in OUTPUTS:
        raise ValueError(f"output must be one of {', '.join(OUTPUTS)}; got {output!r}")
    f_min, f_max = float(f_min), float(f_max)
    if not (math.isfinite(f_min) and math.isfinite(f_max) and 0.0 < f_min < f_max):
        raise ValueError(f"the band needs 0 < f_min < f_max (Hz); got {f_min:g}, {f_max:g}")
    if not (0.0 < tol < 1.0):
        raise ValueError(f"tol must lie in (0, 1); got {tol!r}")
    points = int(points)
    if not 20 <= points <= 5000:
        raise ValueError(f"points must be an integer in 20..5000; got {points}")
    s_ = Strip() if strip is None else strip
    m = NAFION_LI if material is None else material

    def full(f):
        if response_kw.get("sheet_resistance") is not None:
            r = line_response(f, strip=s_, model=model, material=m, method=method, **response_kw)
        else:
            kw = {k: v for k, v in response_kw.items() if k != "sheet_resistance"}
            # the fit reads the response only (the biased circuit's error is not part of it)
            r = frequency_response(f, strip=s_, model=model, material=m, method=method, reference_points=0, **kw)
        if output in ("charge", "current"):
            # fitted as the charge per volt Q = Y/s: the current I = s Q has a zero at s = 0 that
            # a relative fit of Y itself cannot pin
            return 1.0 / (r.Z * 2j * math.pi * f), r
        return {"w": r.H_w, "impedance": r.Z}[output], r

    f_fit = np.geomspace(f_min, f_max, points)
    H, r0 = full(f_fit)
    f_chk = np.geomspace(f_min, f_max, 4 * points)
    Hc, _ = full(f_chk)
    # s scaled by the band's geometric centre: the least-squares problems stay well conditioned
    w0 = 2.0 * math.pi * math.sqrt(f_min * f_max)
    s = 1j * 2.0 * math.pi * f_fit / w0
    sc = 1j * 2.0 * math.pi * f_chk / w0
    # an undamped dynamic beam has its resonances (poles) and antiresonances (zeros of the tip's
    # response, beam.dynamics.transfer: real on the axis) exactly on the imaginary axis; a fit of H
    # places them only nearly, and its relative error there is unbounded.  Fit G = H Q/Z instead,
    # Q(x) = prod (1 + x^2/x_k^2) over the modes in the band (and above it while the zeros outnumber
    # them), Z alike over the zeros in the band (G is smooth there), and restore both exactly by
    # partial fractions: H_fit/H = G_fit/G, the same relative error.
    xk = xz = np.zeros(0)
    if (output == "w" and response_kw.get("beam") == "dynamic" and not response_kw.get("viscous_modulus")
            and response_kw.get("sheet_resistance") is None and response_kw.get("electrode") is None):
        from scipy.optimize import brentq  # deferred: heavy import (start-up)

        nm = int(response_kw.get("n_modes", DEFAULT_MODES))
        bm = strip_beam(s_, m)
        fk = natural_frequencies("clamped-free", bm, nm)

        def tip(f):
            return transfer(np.atleast_1d(f), bm, "clamped-free", nm)["w"].real

        tw = tip(f_chk)
        fz = [brentq(lambda x: float(tip(x)[0]), f_chk[i], f_chk[i + 1], xtol=1e-14 * f_chk[i], rtol=1e-15)
              for i in np.nonzero(np.sign(tw[:-1]) * np.sign(tw[1:]) < 0)[0]
              if not np.any((fk >= f_chk[i]) & (fk <= f_chk[i + 1]))]  # a sign change at a mode is its pole
        nq = max(int(np.sum(fk <= f_max)), len(fz))
        fk = fk[:nq][fk[:nq] >= f_min] if nq <= fk.size else fk[fk >= f_min]
        xk = 2.0 * math.pi * fk / w0
        xz = 2.0 * math.pi * np.asarray(fz, dtype=float) / w0

    def Q(x):
        return np.prod(1.0 + x[..., None] ** 2 / xk**2, axis=-1)

    def Z(x):
        return np.prod(1.0 + x[..., None] ** 2 / xz**2, axis=-1)

    if xk.size or xz.size:
        H, Hc = H * Q(s) / Z(s), Hc * Q(sc) / Z(sc)
    best = None
    from threadpoolctl import threadpool_limits  # deferred: only the fit needs it

    # small least-squares problems: BLAS threads would only compete for the cores
    with threadpool_limits(1):
        for order in ORDERS:
            poles, res, d = vector_fit(np.concatenate([s, s.conj()]), np.concatenate([H, H.conj()]), order)
            val = d + np.sum(res / (sc[:, None] - poles[None, :]), axis=1)
            err = float(np.max(np.abs(val - Hc) / np.abs(Hc)))
            if best is None or err < best[0]:
                best = (err, poles, res, d)
            if err <= tol:
                break
    err, poles, res, d = best
    if xk.size or xz.size:
        # H = G_fit Z/Q: residue r_j Z(p_j)/Q(p_j) at each fitted pole, G_fit(a) Z(a)/Q'(a) at the
        # restored a = +-i x_k; direct term d lim Z/Q (0 when Q has the higher degree)
        ax = np.concatenate((1j * xk, -1j * xk))
        kk = np.concatenate((np.arange(xk.size), np.arange(xk.size)))
        g_ax = d + np.sum(res / (ax[:, None] - poles[None, :]), axis=1)
        fac = 1.0 + ax[:, None] ** 2 / xk[None, :] ** 2
        fac[np.arange(ax.size), kk] = 2.0 * ax / xk[kk] ** 2  # the derivative of the vanishing factor
        res = np.concatenate((res * Z(poles) / Q(poles), g_ax * Z(ax) / np.prod(fac, axis=1)))
        poles = np.concatenate((poles, ax))
        d = float(d * np.prod(xk**2) / np.prod(xz**2)) if xk.size == xz.size else 0.0
        Hc = Hc * Z(sc) / Q(sc)
    d1 = 0.0
    if output == "current":
        # I = s Q with s = w0 x (x the scaled variable): w0 x (d + r/(x - p)) = d s + w0 r + w0 r p/(x - p)
        d1, d, res = d, float(w0 * np.sum(res).real), w0 * res * poles
        Hc = Hc * sc * w0
    # back to s in rad/s: r/(s/w0 - p) = (r w0)/(s - p w0)
    fit = RationalModel(poles=poles * w0, residues=res * w0, d=d, band=(f_min, f_max), max_rel_error=math.inf,
                        output=output, unit=OUTPUTS[output][1], model=r0.model, method=method, success=False,
                        message="", notes=list(r0.notes), d1=d1)
    err = _stated_error(fit, full, f_chk, Hc, output, w0)
    fit.max_rel_error = err
    fit.success = bool(err <= tol and np.all(fit.poles.real <= 0))
    fit.message = (f"order {fit.order}: max relative error {err:.2e} on {f_chk.size} check frequencies in the band"
                   + ("" if fit.success else f" (> tol {tol:g})"))
    return fit


@dataclass(repr=False)
class ExportedModels:
    """The reduced-order models of a ``freq --export`` file (:func:`load_export`).

    Attributes
    ----------
    models : dict
        Output (``"w"``: tip deflection per volt, m/V; ``"charge"``: electrode charge per volt,
        C/V) -> :class:`RationalModel`, each with its band and stated error.
    thickness_total : float       TOTAL thickness 2e of the strip (m)
    electrode_area : float        2l L (m^2)
    diffusion_coefficient : float D (m^2/s)
    notes : list of str
    """

    models: dict
    thickness_total: float
    electrode_area: float
    diffusion_coefficient: float
    notes: list = field(default_factory=list)

    def __getitem__(self, output) -> RationalModel:
        try:
            return self.models[output]
        except KeyError:
            raise KeyError(f"no exported model {output!r}; the file holds {', '.join(self.models)}") from None

    def __repr__(self):
        parts = [f"{o}: order {m.order}, band {m.band[0]:g}-{m.band[1]:g} Hz, max rel. error {m.max_rel_error:.2g} "
                 f"({m.unit})" for o, m in self.models.items()]
        return "ExportedModels(" + "; ".join(parts) + ")"

    def frequency_response(self, f, output="w"):
        """``H(2 pi i f)`` of one exported model (complex, shape of ``f``; the stated error holds in its band)."""
        return self[output](f)

    def to_control(self, output="w", form="ss"):
        """A ``control.StateSpace`` (``form="ss"``) or ``control.TransferFunction`` (``"tf"``) of one model."""
        return self[output].to_control(form)


def load_export(path) -> ExportedModels:
    """Read a ``freq --export`` JSON file back into its models.

    Parameters
    ----------
    path : str or path
        The file ``ipmc-asym freq --export F.json`` wrote (read through the bounded input reader).

    Returns
    -------
    ExportedModels
        ``[output]`` a :class:`RationalModel` (``"w"`` m/V, ``"charge"`` C/V; ``current = s x
        charge``), ``.frequency_response(f, output)``, ``.to_control(output, form)`` (python-control,
        the optional ``control`` extra).

    Raises
    ------
    ValueError
        One line: not JSON, or a key missing or malformed (named).

    Examples
    --------
    >>> import os, tempfile, json
    >>> import ipmc_asym as ia
    >>> tf = ia.transfer_function(0.01, 100.0)
    >>> path = os.path.join(tempfile.mkdtemp(), "tf.json")
    >>> with open(path, "w") as fh:
    ...     _ = fh.write(json.dumps({"models": {"w": tf.to_dict()}, "thickness_total": 2e-4,
    ...                              "electrode_area": 1e-4, "diffusion_coefficient": 1e-10}))
    >>> m = ia.load_export(path)
    >>> bool(m.frequency_response(1.0) == tf(1.0))
    True
    """
    name = os.path.basename(os.fspath(path))
    try:
        doc = json.loads(read_input_text(path, "export file"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{name}: not a JSON file written by freq --export ({exc.__class__.__name__})") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("models"), dict) or not doc["models"]:
        raise ValueError(f"{name}: no 'models' object (a file written by freq --export)")
    models = {o: RationalModel.from_dict(m, f"{name} models[{o!r}]") for o, m in doc["models"].items()}
    try:
        geo = {k: float(doc[k]) for k in ("thickness_total", "electrode_area", "diffusion_coefficient")}
    except KeyError as exc:
        raise ValueError(f"{name}: no key {exc.args[0]!r}") from None
    except (TypeError, ValueError):
        raise ValueError(f"{name}: thickness_total, electrode_area, diffusion_coefficient must be numbers") from None
    return ExportedModels(models=models, notes=list(doc.get("notes", [])), **geo)
