"""The derived quantities of the model, each written once: the dimensionless groups
``A0..A5`` (paper eqs (22)-(23)), the core Debye length, the core conductivity, the
geometric capacitance and ``B1`` from electroneutrality.

Every function is vectorised (numpy broadcasting over its array arguments) and takes a
:class:`~ipmc_asym.model.params.Material` for the constants (``F``, ``R``, ``T``, ``phi4``,
``rho2``, ``Z3``, ``D``).  ``C_moy`` defaults to ``material.C_moy`` and may be passed as an
array (per-sample values in uncertainty studies).  ``thickness`` and ``width`` are TOTAL
(``2e``, ``2l``); the groups are built on ``|phi0|`` (see :mod:`ipmc_asym.model.params`).

Layer rule: model layer, numpy only (``params`` imports this module, not the reverse, so
``Material`` and ``Strip`` appear in annotations only; ``from __future__ import annotations``
keeps them unevaluated).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Groups", "make_groups", "A0", "A1", "A2", "A3", "A5", "inverse_thermal_voltage",
           "thermal_voltage", "debye_length", "debye_length_m", "kappa", "geometric_capacitance",
           "b1_neutral", "moment_scale", "electrode_line_resistance", "line_propagation", "pressure_beta"]


def _cm(material: Material, C_moy):
    return material.C_moy if C_moy is None else np.asarray(C_moy, dtype=float)


def inverse_thermal_voltage(material: Material) -> float:
    """``F / (R T)`` (1/V): ``A2 = |phi0| F / (R T)``."""
    return material.F / (material.R * material.T)


def thermal_voltage(material: Material) -> float:
    """``R T / F`` (V), the potential scale of the core (``phi = (R T / F) psi``)."""
    return 1.0 / inverse_thermal_voltage(material)


def A0(thickness, voltage, deps, material: Material, C_moy=None):
    """``A0 = |phi0| deps / (e^2 phi4 F C_moy)`` (dimensionless; paper eqs (22)-(23)).

    Parameters
    ----------
    thickness : array_like   TOTAL thickness 2e, m
    voltage : array_like     phi0, V (only ``|phi0|`` enters)
    deps : array_like        eps_moy - eps0, F/m
    material : Material
    C_moy : array_like, optional   mol/m^3 (default ``material.C_moy``)
    """
    e = 0.5 * np.asarray(thickness, dtype=float)
    return np.abs(np.asarray(voltage, dtype=float)) * deps / (e * e * material.phi4 * material.F
                                                                * _cm(material, C_moy))


def A1(thickness, voltage, eps0, material: Material, C_moy=None):
    """``A1 = |phi0| eps0 / (e^2 phi4 F C_moy)`` (dimensionless; paper eqs (22)-(23)).

    Same arguments as :func:`A0` with ``eps0`` (F/m, permittivity at ``C = 0``).
    """
    return A0(thickness, voltage, eps0, material, C_moy)


def A2(voltage, material: Material):
    """``A2 = F |phi0| / (R T)`` (dimensionless; paper eqs (22)-(23)); even in ``phi0``.

    Parameters
    ----------
    voltage : array_like   phi0, V
    material : Material
    """
    return np.abs(np.asarray(voltage, dtype=float)) * inverse_thermal_voltage(material)


def A3(material: Material, C_moy=None):
    """``A3 = -rho2 Z3 / (C_moy F)`` (dimensionless; paper eqs (22)-(23)): the solvent pressure
    coupling; voltage-independent.

    Parameters
    ----------
    material : Material   ``rho2`` (kg/m^3), ``Z3`` (C/kg), ``F`` (C/mol)
    C_moy : array_like, optional   mol/m^3 (default ``material.C_moy``)
    """
    return -material.rho2 * material.Z3 / (_cm(material, C_moy) * material.F)


def pressure_beta(material: Material, C_moy=None):
    """``beta = (v1 - M1 v2/M2) C_moy`` (dimensionless): the pressure term of the Nernst-Planck
    law (paper eq. (5)) relative to migration is ``beta (C/C_moy + A3)``
    (``derivations/pressure.py``); 0 drops it (the paper's model).

    Parameters
    ----------
    material : Material   ``v1``, ``v2`` (m^3/mol), ``M1``, ``M2`` (kg/mol)
    C_moy : array_like, optional   mol/m^3 (default ``material.C_moy``)
    """
    m = material
    return (m.v1 - m.M1 * m.v2 / m.M2) * _cm(material, C_moy)


def moment_scale(width, thickness, voltage, F, C_moy):
    """``A5 = 6 l e^2 F |phi0| C_moy`` (N m): ``M_A = A5 I`` (paper eqs (23), (27)); even in ``phi0``.

    Parameters
    ----------
    width, thickness : array_like   TOTAL width 2l and thickness 2e, m
    voltage : array_like            phi0, V
    F : float                       C/mol
    C_moy : array_like              mol/m^3
    """
    l = 0.5 * np.asarray(width, dtype=float)  # noqa: E741
    e = 0.5 * np.asarray(thickness, dtype=float)
    return 6.0 * l * e * e * F * np.abs(np.asarray(voltage, dtype=float)) * C_moy


def A5(width, thickness, voltage, material: Material, C_moy=None):
    """``A5 = 6 l e^2 F |phi0| C_moy`` (N m; paper eqs (23), (27)), :func:`moment_scale` of a material."""
    return moment_scale(width, thickness, voltage, material.F, _cm(material, C_moy))


def debye_length_m(eps_core, material: Material, C_moy=None):
    """Core Debye length ``lambda_D = sqrt(eps_core R T / (phi4 F^2 C_moy))`` (m).

    Parameters
    ----------
    eps_core : array_like   permittivity of the neutral core, F/m
    material : Material
    C_moy : array_like, optional   mol/m^3
    """
    m = material
    return np.sqrt(eps_core * m.R * m.T / (m.phi4 * m.F * m.F * _cm(m, C_moy)))


def debye_length(thickness, eps_core, material: Material, C_moy=None):
    """Core Debye length over ``e``: ``lambda = lambda_D / e`` (dimensionless).

    Equal to ``sqrt((A0 + A1)/A2)`` but defined at zero volts too (all three groups scale
    with ``|phi0|``).  ``thickness`` is TOTAL (2e, m); ``eps_core`` in F/m.
    """
    return debye_length_m(eps_core, material, C_moy) / (0.5 * np.asarray(thickness, dtype=float))


def kappa(material: Material, C_moy=None):
    """Core ionic conductivity ``kappa = phi4 F^2 D C_moy / (R T)`` (S/m, Nernst-Einstein)."""
    m = material
    return m.phi4 * m.F * m.D * _cm(m, C_moy) * inverse_thermal_voltage(m)


def geometric_capacitance(thickness, eps_core):
    """Geometric capacitance of the core ``C_g = eps_core / (2e)`` (F/m^2); ``thickness`` = 2e (m).

    ``C_g / C_d(0) = lambda`` with the Debye-Hueckel layer capacitance ``C_d(0) = eps_core /
    (2 lambda_D)`` of the two electrodes in series.
    """
    return eps_core / np.asarray(thickness, dtype=float)


def electrode_line_resistance(width, sheet_resistance):
    """Series resistance per unit length of the two electrodes, ``r = 2 R_s/(2l)`` (Ohm/m).

    The current that crosses the thickness beyond ``x`` flows out along one electrode and
    back along the other: both sheets (width ``2l``, TOTAL, m; ``R_s`` in Ohm/sq) are in
    series (``derivations/line.py``).
    """
    return 2.0 * np.asarray(sheet_resistance, dtype=float) / np.asarray(width, dtype=float)


def line_propagation(length, sheet_resistance, Z_area):
    """``g = gamma L = L sqrt(2 R_s/Z_area)`` (dimensionless, complex, ``Re g >= 0``).

    ``gamma^2 = r y`` with ``r = 2 R_s/(2l)`` and the shunt admittance per length
    ``y = 2l/Z_area`` (``Z_area`` in Ohm m^2): the width cancels (``derivations/line.py``).
    """
    z = np.asarray(Z_area, dtype=complex)
    return np.asarray(length, dtype=float) * np.sqrt(2.0 * np.asarray(sheet_resistance, dtype=float) / z)


def b1_neutral(A2, rho):
    """``B1 = C(+e)/C_moy`` from electroneutrality of a neutral core (paper section 4).

    The positive root of ``(1 - rho)/2 (1 - e^{-2 A2}) B^2 + (2 rho - 1)(1 - e^{-A2}) B -
    rho A2 = 0`` (the first integral ``G(B1) = G(B1 e^{-A2})``, ``G(C) = (1 - rho) C^2/2 +
    (2 rho - 1) C - rho ln C``; ``rho = eps0/eps_core = A1/(A0 + A1)``).  Constant model
    (``rho = 1``): ``A2/(1 - e^{-A2})``; linear (``rho = 0``): ``2/(1 + e^{-A2})``.  The
    compiled kernels evaluate the same root from ``derivations.model:b1_quadratic_rho``.

    Parameters
    ----------
    A2 : array_like   >= 0 (``B1 = 1`` at 0)
    rho : array_like  in [0, 1]

    Returns
    -------
    ndarray (dimensionless)
    """
    a2, r = np.broadcast_arrays(np.asarray(A2, dtype=float), np.asarray(rho, dtype=float))
    em1 = -np.expm1(-a2)  # 1 - e^{-A2}
    a = 0.5 * (1.0 - r) * em1 * (2.0 - em1)  # (1 - rho)/2 (1 - e^{-2 A2})
    bq = (2.0 * r - 1.0) * em1
    c = -r * a2
    disc = np.sqrt(bq * bq - 4.0 * a * c)
    with np.errstate(divide="ignore", invalid="ignore"):
        # positive root, cancellation-free; a = 0 is the constant model's linear equation
        quad = np.where(bq <= 0, (-bq + disc) / (2.0 * a), (-2.0 * c) / (bq + disc))
        lin = a2 / em1
    out = np.where(a > 0, quad, lin)
    return np.where(a2 > 0, out, 1.0)


@dataclass(frozen=True)
class Groups:
    """Dimensionless groups of the system (paper eqs (22)-(23)), built on ``|phi0|``.

    ``sign`` is the sign of the voltage (+1, -1, or 0): the solution for a negative voltage
    is the mirror image of the one for ``|phi0|``, so ``I`` carries ``sign``.
    """

    C_moy: float
    A0: float
    A1: float
    A2: float
    A3: float
    A5: float
    sign: float
    e: float
    l: float  # noqa: E741
    phi0: float
    extra: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def debye(self) -> float:
        """Core Debye length relative to ``e``: ``lambda = sqrt((A0 + A1) / A2)``.

        Independent of the voltage (all three groups scale with ``|phi0|``); stored from the
        dimensional data so that it is defined at zero volts too.
        """
        return self.extra["debye"]


def make_groups(strip: Strip, material: Material, eps0: float, deps: float) -> Groups:
    """Dimensionless groups for a strip, a material and ``eps = eps0 + deps * C / C_moy``.

    Parameters
    ----------
    strip : Strip
    material : Material
    eps0 : float
        Permittivity at zero concentration, F/m (``>= 0``).
    deps : float
        ``eps_moy - eps0``, F/m (``>= 0``; not both zero).

    Returns
    -------
    Groups
        :func:`A0`, :func:`A1`, :func:`A2`, :func:`A3` (dimensionless) and :func:`A5` (N m)
        at ``|phi0|``, and the Debye length :func:`debye_length`.
    """
    m = material
    th, v = strip.thickness, float(strip.voltage)
    sign = math.copysign(1.0, v) if v != 0.0 else 0.0
    return Groups(
        C_moy=m.C_moy,
        A0=float(A0(th, v, deps, m)),
        A1=float(A1(th, v, eps0, m)),
        A2=float(A2(v, m)),
        A3=float(A3(m)),
        A5=float(A5(strip.width, th, v, m)),
        sign=sign,
        e=strip.e,
        l=strip.l,
        phi0=v,
        extra={"debye": float(debye_length(th, eps0 + deps, m))},
    )
