r"""Metal electrode layers on the strip's faces: the composite beam section.

The paper's beam (section 3) is the bare membrane: ``E I_p`` with ``I_p = 4 l e^3/3``.  A real
IPMC carries a metal layer of thickness ``t_m`` on each face (platinum or gold, a few µm),
whose modulus (of order 1e11 Pa against 1e8 Pa for the hydrated membrane) makes it a large
share of the bending stiffness and of the mass.  This module gives the symmetric three-layer
section (membrane ``2e`` between two layers ``t_m``; TOTAL width ``2l``):

.. math::

    EI = E_p \frac{2l (2e)^3}{12}
         + E_m \frac{2l \left[(2e + 2t_m)^3 - (2e)^3\right]}{12}, \qquad
    \rho A = \rho_p\, 2l\, 2e + 2 \rho_m\, 2l\, t_m .

The section is symmetric, so its neutral axis stays at mid-thickness: the moment ``M_A`` the
charged layers exert about it (paper eq. (w)) is unchanged, only the stiffness and the mass
change.  The electrochemistry keeps the membrane thickness ``2e``.  The strain check reads the
polymer's face strain ``e |kappa|`` (the membrane's face at ``z = +-e``, where the small-strain
law of the polymer is assumed; the metal's outer face strains ``(e + t_m)|kappa|``).

Assumptions (stated, not from the paper): perfect bonding (plane sections), the layers cover
the whole length (with a partial electrode, ``electrode = (x1, x2)``, only the active moment is
partial, the layer's stiffness is taken over the whole strip), the metal is elastic (the
Kelvin-Voigt viscosity acts on the membrane's share ``E_p I_p`` of the stiffness only).

Layer rule: part of ``model``; imports numpy only (``params`` builds on it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["METALS", "Electrode", "NO_ELECTRODE", "ELECTRODE_KEYS", "electrode_from_spec", "composite_stiffness",
           "composite_mass", "membrane_share", "beam_label"]

#: metal -> (Young's modulus Pa, density kg/m^3, source read).  Bulk handbook values of the
#: pure metals; a plated layer (porous, nanocrystalline) may differ: ``--electrode-modulus`` /
#: ``--electrode-density`` override them.
METALS = {
    "platinum": (171.0e9, 21450.0,
                 "platinum: elastic modulus 171 GPa (tension, static, annealed at 700 C, 20 C) and density "
                 "21.45 g/cm^3 (20 C): Central Metals, 'Platinum and its applications' "
                 "(centralmetals.co.uk/Platinum.php3); the same 171 GPa and 21.45 g/cm^3 in AZoM, 'Platinum (Pt) - "
                 "Properties, Applications' (azom.com/article.aspx?ArticleID=9235); density 21.45e3 kg/m^3 also in "
                 "I. S. Grigoriev, E. Z. Meilikhov, Handbook of Physical Quantities, CRC Press 1997, table 5.1 "
                 "(as quoted by The Physics Factbook, hypertextbook.com/facts/2004/OliviaTai.shtml)"),
    "gold": (78.0e9, 19300.0,
             "gold: Young's modulus 78 GPa and density of the solid 19300 kg/m^3: WebElements, 'Gold: physical "
             "properties' (webelements.com/gold/physics.html)"),
}

#: keys of an electrode specification (material ``[electrode]`` table, scene tables, CLI)
ELECTRODE_KEYS = ("thickness", "metal", "modulus", "density")


def _num(name, value, unit, *, zero_ok=False):
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = float("nan")
    if isinstance(value, bool) or not math.isfinite(v) or v < 0.0 or (v == 0.0 and not zero_ok):
        rel = ">= 0" if zero_ok else "> 0"
        raise ValueError(f"{name} must be a finite number {rel} {unit}; got {value!r}")
    return v


@dataclass(frozen=True)
class Electrode:
    """Two metal layers, one on each face of the membrane (SI).

    Attributes
    ----------
    thickness : float  ``t_m``, thickness of EACH layer, m (>= 0; 0 = the bare membrane)
    modulus : float    ``E_m``, Young's modulus of the metal, Pa (> 0 when ``thickness > 0``)
    density : float    ``rho_m``, density of the metal, kg/m^3 (dynamics only)
    metal : str        name of the metal of :data:`METALS` the values come from ("" if given)
    source : str       where the values come from (citation or "given")
    """

    thickness: float = 0.0
    modulus: float = 0.0
    density: float = 0.0
    metal: str = ""
    source: str = ""

    def __post_init__(self):
        t = _num("electrode thickness", self.thickness, "m", zero_ok=True)
        if t > 0.0:
            _num("electrode modulus", self.modulus, "Pa")
            _num("electrode density", self.density, "kg/m^3", zero_ok=True)

    @property
    def present(self) -> bool:
        """True when the layers have a thickness (else the beam is the bare membrane)."""
        return self.thickness > 0.0


#: the paper's beam: no metal layer
NO_ELECTRODE = Electrode()


def electrode_from_spec(spec=None, labels=None, base: Electrode = NO_ELECTRODE) -> Electrode:
    """The one electrode parser (material ``[electrode]`` tables and the command line).

    Parameters
    ----------
    spec : dict or None
        Any of :data:`ELECTRODE_KEYS`: ``thickness`` (m, each layer), ``metal`` (a key of
        :data:`METALS`: its modulus and density with their source), ``modulus`` (Pa) and
        ``density`` (kg/m^3), which override the metal's.
    labels : dict, optional
        How to name each key in error messages (e.g. ``{"thickness": "--electrode-thickness"}``).
    base : Electrode
        The layer the spec modifies (a material set's).

    Returns
    -------
    Electrode

    Raises
    ------
    ValueError
        One line naming the key (unknown key or metal, value out of range, a layer without a
        modulus).
    """
    spec = {} if spec is None else dict(spec)
    labels = labels or {}

    def name(k):
        return labels.get(k, f"electrode.{k}")

    for k in spec:
        if k not in ELECTRODE_KEYS:
            raise ValueError(f"unknown key {k!r} in [electrode]; allowed: {', '.join(ELECTRODE_KEYS)}")
    t, Em, rho, metal, src = base.thickness, base.modulus, base.density, base.metal, base.source
    if "metal" in spec:
        metal = spec["metal"]
        if metal not in METALS:
            raise ValueError(f"{name('metal')} must be one of {', '.join(METALS)}; got {metal!r}")
        Em, rho, src = METALS[metal]
    if "thickness" in spec:
        t = _num(name("thickness"), spec["thickness"], "m", zero_ok=True)
    given = []
    if "modulus" in spec:
        Em = _num(name("modulus"), spec["modulus"], "Pa")
        given.append(f"modulus {Em:g} Pa")
    if "density" in spec:
        rho = _num(name("density"), spec["density"], "kg/m^3", zero_ok=True)
        given.append(f"density {rho:g} kg/m^3")
    if given:
        src = (src + "; " if src else "") + "given by the user: " + ", ".join(given)
    if t > 0.0 and not Em > 0.0:
        raise ValueError(f"{name('thickness')} > 0 needs the layer's modulus: give {name('metal')} "
                         f"({' or '.join(METALS)}) or {name('modulus')}")
    if t == 0.0:  # no layer: the bare membrane, whatever metal was named
        return NO_ELECTRODE
    if not metal and "density" not in spec and rho == 0.0:
        src = (src + "; " if src else "") + "no density given (0 kg/m^3: the layers add no mass)"
    return Electrode(t, Em, rho, metal, src)


def composite_stiffness(E, width, thickness, electrode: Electrode = NO_ELECTRODE):
    """Bending stiffness of the symmetric three-layer section (N m^2), vectorised.

    Parameters
    ----------
    E : array_like
        Membrane modulus ``E_p`` (Pa).
    width, thickness : array_like
        TOTAL width ``2l`` and membrane thickness ``2e`` (m).
    electrode : Electrode
        The layers (``thickness`` each, modulus ``E_m``).

    Returns
    -------
    ndarray
        ``E_p 2l (2e)^3/12 + E_m 2l [(2e + 2 t_m)^3 - (2e)^3]/12``; without a layer exactly
        ``E_p I_p`` with ``I_p = 4 l e^3/3`` (paper section 3), the bare membrane's own
        expression, so that no layer means the paper's numbers to the last bit.
    """
    w = np.asarray(width, dtype=float)
    h = np.asarray(thickness, dtype=float)
    l = 0.5 * w  # noqa: E741 - the paper's name
    e = 0.5 * h
    EI = np.asarray(E, dtype=float) * (4.0 * l * e**3 / 3.0)
    if not electrode.present:
        return EI
    H = h + 2.0 * electrode.thickness
    return EI + electrode.modulus * w * (H**3 - h**3) / 12.0


def composite_mass(rho, width, thickness, electrode: Electrode = NO_ELECTRODE):
    """Mass per unit length (kg/m): ``rho_p 2l 2e + 2 rho_m 2l t_m`` (vectorised).

    ``rho`` is the membrane's density (kg/m^3); without a layer exactly ``rho 2l 2e``.
    """
    m = np.asarray(rho, dtype=float) * np.asarray(width, dtype=float) * np.asarray(thickness, dtype=float)
    if not electrode.present:
        return m
    return m + 2.0 * electrode.density * np.asarray(width, dtype=float) * electrode.thickness


def membrane_share(E, width, thickness, electrode: Electrode = NO_ELECTRODE):
    """``E_p I_p / EI``: the share of the stiffness the membrane carries (1 without a layer).

    With an elastic metal the Kelvin-Voigt moment is ``E_p I_p tau_v w''_t``: the composite
    beam's viscous time is ``tau_v`` times this share.
    """
    if not electrode.present:
        return 1.0
    w = np.asarray(width, dtype=float)
    h = np.asarray(thickness, dtype=float)
    EIp = np.asarray(E, dtype=float) * w * h**3 / 12.0
    return EIp / composite_stiffness(E, width, thickness, electrode)


def beam_label(electrode: Electrode = NO_ELECTRODE) -> str:
    """One line saying which beam a result used (every output prints it)."""
    if not electrode.present:
        return "bare membrane (E I_p, no electrode layer)"
    metal = electrode.metal or "metal"
    bulk = electrode.metal in METALS and electrode.modulus == METALS[electrode.metal][0]
    # the preset is the solid metal's: said, since it decides most of the stiffness
    caveat = (f"; E_m is solid {metal}'s: a porous or cracked plated layer is softer, --electrode-modulus sets a "
              "measured one") if bulk else ""
    return (f"membrane + two {metal} layers t_m = {electrode.thickness * 1e6:.4g} um each, "
            f"E_m = {electrode.modulus:.4g} Pa, rho_m = {electrode.density:.4g} kg/m^3 (composite section; "
            f"strain check on the membrane's face{caveat})")
