"""Strip geometry, material data and the dimensionless groups of the model.

Layer rule: this module is the bottom of the stack (parameters -> permittivity ->
kernels -> layers/BVP -> beam -> sweeps/scenes -> plots/CLI).  It imports numpy only.
The derived quantities (``A0..A5``, Debye length, conductivity, ``B1``) are written once in
:mod:`ipmc_asym.model.groups`; ``Groups``, ``make_groups``, ``moment_scale`` and
``debye_length`` are re-exported here.

Conventions
-----------
* SI units everywhere inside the library.
* ``thickness`` and ``width`` are the TOTAL thickness ``2e`` and TOTAL width ``2l``; the
  paper's ``e`` and ``l`` are halves and appear here as ``Strip.e`` and ``Strip.l``.
* The voltage ``phi0`` is the potential of the face ``z = -e`` (anode) relative to the face
  ``z = +e`` (cathode).  A negative voltage is the mirror image ``z -> -z`` of ``|phi0|``.
  The dimensionless groups are built on ``|phi0|`` (the scale), so ``A2 >= 0`` and the
  moment integral ``I`` is odd in ``phi0`` (``M_A = A5 * I`` with ``A5 >= 0``).

Sources of the ``nafion-li`` preset (seed paper section 4): ``Z3 = -9e4 C/kg`` (Collette),
``rho3 = 2078 kg/m^3`` and ``phi4 = 0.38`` (Nemat-Nasser & Li 2000), ``E = 1.3e8 Pa``
(Satterfield & Benziger 2009), ``rho2 = 1000 kg/m^3``, ``T = 300 K``, ``F = 96487 C/mol``,
``R = 8.31 J/(mol K)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ipmc_asym.base.settings import (
    C_MOY_RANGE,
    DIFFUSION_RANGE,
    FREQUENCY_RANGE,
    MAX_DIMENSION,
    MAX_SHEET_RESISTANCE,
    MAX_VOLTAGE,
    MIN_DIMENSION,
    MIN_THICKNESS,
    STRAIN_LIMIT,
    VALIDATED_VOLTAGE,
)
from ipmc_asym.base.units import parse_length, parse_pressure, parse_voltage
from ipmc_asym.model import material_data
from ipmc_asym.model.electrode import NO_ELECTRODE, Electrode, composite_stiffness, electrode_from_spec
from ipmc_asym.model.groups import Groups, debye_length, make_groups, moment_scale

__all__ = [
    "as_material",
    "as_strip",
    "C_MOY_PAPER",
    "V1_LI_DEFAULT",
    "V1_LI_SOURCE",
    "V1_LI_RANGE",
    "V2_WATER_SOURCE",
    "M_SOURCE",
    "D_CATION_DEFAULT",
    "D_CATION_SOURCE",
    "SHEET_RESISTANCE_SOURCE",
    "Material",
    "Strip",
    "Groups",
    "NOMINAL_STRIP",
    "NAFION_LI",
    "MATERIALS",
    "check_positive",
    "check_finite",
    "check_min_thickness",
    "check_dimension",
    "check_within",
    "check_diffusion",
    "check_c_moy",
    "check_voltage_cap",
    "check_voltages",
    "check_frequencies",
    "check_finite_response",
    "make_groups",
    "moment_scale",
    "debye_length",
    "second_moment",
    "MATERIAL_KEYS",
    "material_from_spec",
    "named_material",
    "FALLBACK_DEFAULTS",
    "bending_stiffness",
    "ELECTRODE_SPEC_KEYS",
    "set_thickness",
]

#: Default cation diffusion coefficient (m^2/s) of the ``nafion-li`` preset and its source.
D_CATION_DEFAULT = 1.0e-10
D_CATION_SOURCE = (
    "D = 1e-10 m^2/s is an assumption for Li+, not a measurement: the radiotracer study of "
    "self-diffusion in Nafion-117 (A. Goswami et al., J. Phys. Chem. B 105 (2001) 9196) lists Na+, "
    "K+, Cs+ and Ag+ (and divalent ions), not Li+, and no diffusion coefficient of Li+ in Nafion was "
    "found in the sources read; every dynamic time scales as 1/D (ipmc-asym validate reports the D "
    "that gives the paper's ~1 s)"
)

#: What is known of the electrodes' sheet resistance R_s (Ohm/sq); the default is 0 (ideal
#: electrodes, the paper's assumption: the same voltage along the whole strip).
SHEET_RESISTANCE_SOURCE = (
    "R_s is not in the paper (default 0: ideal electrodes). Measured: about 2.5 Ohm/sq for Pt electrolessly "
    "plated on Nafion-117 after one round of NaBH4 reduction (four-point probe, 10 x 50 mm samples; E. Manaf et "
    "al., Polymers 16 (2024) 2338, abstract); the same group reports that R_s depends strongly on the plating "
    "conditions (Actuators 13 (2024) 350). No range is given here: one measured value was read"
)

#: Partial molar volumes and molar masses of the pressure term of the Nernst-Planck law (paper
#: eq. (5); option ``pressure_term``), SI, with the sources read.  The paper names them
#: (``v_k``, ``M_k`` in its nomenclature) but gives no values.
V1_LI_DEFAULT = -0.87e-6
V1_LI_SOURCE = (
    "v1 = -0.87 cm^3/mol: standard partial molal volume of Li+(aq) at 25 C on the conventional scale "
    "(V(H+) = 0), E. L. Shock and H. C. Helgeson, Geochim. Cosmochim. Acta 52 (1988) 2009, as tabulated in "
    "the WORM-db thermodynamic database (github.com/worm-portal/WORM-db, wrm_data_latest.csv, row Li+, "
    "column V).  No absolute (single-ion) aqueous value was found; the only other value read, ~5 cm^3/mol, "
    "is the volume of Li+ in carbonate solvents (propylene/ethylene/dimethyl carbonate; abstract of "
    "'Ion solvation in carbonate-based lithium battery electrolyte solutions'), not water"
)
V1_LI_RANGE = (-0.87e-6, 5.0e-6)
V2_WATER_SOURCE = (
    "v2 = M2/rho2 = 18.015e-6 m^3/mol: molar volume of water from the paper's rho2 = 1000 kg/m^3 "
    "(section 4) and M2 (a dilute solution: the partial molar volume of the solvent is its molar volume)"
)
M_SOURCE = (
    "M1 = 6.941e-3 kg/mol (Li), M2 = 18.0154e-3 kg/mol (H2O from H 1.008, O 15.9994): the atomic masses "
    "of the CHARMM water/ion parameter file par_water_ions.prm (LIT 6.94100, HT 1.00800, OT 15.99940)"
)

#: The value the paper states (section 4) and uses; the formula with the quoted data gives
#: about 3162 mol/m^3 (docs/design.md, slip 1).
C_MOY_PAPER = 3082.0


def check_finite(name: str, value, allowed: str = "a finite number") -> float:
    """Return ``value`` as float or raise a one-line ``ValueError`` naming ``name``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be {allowed}; got {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be {allowed}; got {value!r}")
    return v


def check_dimension(name: str, value, floor: bool = True) -> float:
    """``value`` (m) as a float, finite, within :data:`ipmc_asym.base.settings.MIN_DIMENSION` ..
    :data:`ipmc_asym.base.settings.MAX_DIMENSION`, else a one-line ``ValueError`` naming ``name``
    (``floor=False``: no MIN_DIMENSION, where a stricter floor of its own follows, the thickness's)."""
    v = check_positive(name, value, "m")
    if v > MAX_DIMENSION:
        raise ValueError(f"{name} must be at most {MAX_DIMENSION:g} m (a numerical guard: products such as the "
                         f"charge 2l L sigma and the bending stiffness stay finite); got {value!r}")
    if floor and v < MIN_DIMENSION:
        raise ValueError(f"{name} must be at least {MIN_DIMENSION:g} m (a numerical guard: the beam's formulas divide "
                         f"by it); got {value!r}")
    return v


def check_voltage_cap(voltage, name: str = "voltage") -> None:
    """One-line ``ValueError`` naming ``name`` where a finite voltage (V, scalar or array) passes
    :data:`ipmc_asym.base.settings.MAX_VOLTAGE` in magnitude (a numerical guard, for every entry)."""
    v = np.abs(np.asarray(voltage, dtype=float))
    m = float(np.max(v)) if v.size else 0.0
    if m > MAX_VOLTAGE:
        raise ValueError(f"{name}: |phi0| up to {MAX_VOLTAGE:g} V allowed (the kernels are checked finite up to "
                         f"there; the model is validated to {VALIDATED_VOLTAGE:g} V); got {m:.3g} V")


def check_voltages(voltage, name: str = "voltage") -> None:
    """One-line ``ValueError`` naming ``name`` where a voltage (V, scalar or array) is not finite
    (NaN, inf) or passes :data:`ipmc_asym.base.settings.MAX_VOLTAGE` in magnitude."""
    v = np.asarray(voltage, dtype=float)
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be finite (volts)")
    check_voltage_cap(v, name)


def check_frequencies(f):
    """``f`` (Hz) as a float array, each within :data:`~ipmc_asym.base.settings.FREQUENCY_RANGE`, else a
    one-line ``ValueError`` (NaN and inf too)."""
    f = np.asarray(f, dtype=float)
    lo, hi = FREQUENCY_RANGE
    inside = (f >= lo) & (f <= hi)  # NaN fails too
    if not np.all(inside):
        raise ValueError(f"frequencies must be finite and within {lo:g}..{hi:g} Hz (a numerical guard: the closed "
                         f"forms are checked finite there); got {np.min(f):g}..{np.max(f):g} Hz")
    return f


def check_finite_response(f, outputs: dict) -> None:
    """A numerical check of a spectrum: one line naming the first output that is not a finite number
    and its frequency (a frequency, ``D`` or ``R_s`` so extreme that the closed forms overflow, or an
    undamped resonance hit exactly), so that no such number is printed."""
    f = np.asarray(f, dtype=float).reshape(-1)
    for name, a in outputs.items():
        bad = ~np.isfinite(np.asarray(a)).reshape(-1)
        if np.any(bad):
            k = int(np.flatnonzero(bad)[0])
            raise ValueError(f"f: {name} is not a finite number at {f[k % f.size]:.4g} Hz (an undamped resonance "
                             "hit exactly, or a frequency, diffusion coefficient or sheet resistance beyond what the "
                             "closed forms hold); move or narrow the frequencies, or check those inputs")


def check_min_thickness(thickness) -> None:
    """One-line ``ValueError`` where a TOTAL thickness is below ``settings.MIN_THICKNESS``.

    No rung describes such a film (the continuum model itself does not): refuse at once
    instead of sending the caller to a BVP that takes seconds and then fails.
    """
    th = np.asarray(thickness, dtype=float)
    smallest = float(np.fmin.reduce(th, axis=None)) if th.size else math.inf  # NaN-blind, no copy
    if smallest < MIN_THICKNESS:
        raise ValueError(
            f"thickness (total, 2e) = {smallest:.3g} m is below {MIN_THICKNESS:g} m: "
            "the continuum model does not describe films spanning only a few ionic clusters "
            "(settings.MIN_THICKNESS, docs/design.md)")


def check_positive(name: str, value, unit: str = "") -> float:
    """Finite and strictly positive, else ``ValueError`` naming the parameter and range."""
    u = f" {unit}" if unit else ""
    v = check_finite(name, value, f"a finite number > 0{u}")
    if v <= 0.0:
        raise ValueError(f"{name} must be a finite number > 0{u}; got {value!r}")
    return v


def check_within(name: str, value, bounds, unit: str, why: str) -> float:
    """``value`` as a float within ``bounds`` = (low, high), else a one-line ``ValueError`` naming
    ``name``, the range with its ``unit`` and ``why`` it holds."""
    lo, hi = bounds
    allowed = f"a finite number within {lo:g}..{hi:g} {unit} ({why})"
    v = check_finite(name, value, allowed)
    if not lo <= v <= hi:
        raise ValueError(f"{name} must be {allowed}; got {value!r}")
    return v


def check_diffusion(value, name: str = "cation diffusion coefficient D") -> float:
    """``value`` (m^2/s) within :data:`ipmc_asym.base.settings.DIFFUSION_RANGE`, else one line naming ``name``."""
    return check_within(name, value, DIFFUSION_RANGE, "m^2/s", "a numerical guard: every dynamic time scales as 1/D")


def check_sheet_resistance(value, name: str = "sheet_resistance") -> float:
    """``value`` (Ohm/sq, each electrode) within 0..:data:`~ipmc_asym.base.settings.MAX_SHEET_RESISTANCE`,
    else one line naming ``name``."""
    return check_within(name, value, (0.0, MAX_SHEET_RESISTANCE), "Ohm/sq",
                        "a numerical guard: the electrode line overflows past it")


def check_c_moy(value, name: str = "c_moy") -> float:
    """``value`` (mol/m^3) within :data:`ipmc_asym.base.settings.C_MOY_RANGE`, else one line naming ``name``."""
    return check_within(name, value, C_MOY_RANGE, "mol/m^3",
                        "a numerical guard: the Debye length goes as C_moy^-1/2")


@dataclass(frozen=True)
class Material:
    """Ionic polymer data (SI).  ``c_moy`` is ``"paper"``, ``"formula"`` or a number (mol/m^3).

    Attributes
    ----------
    Z3 : float   mass charge of the polymer backbone, C/kg (negative)
    rho3 : float density of the solid phase, kg/m^3
    phi4 : float volume fraction of the solution, in (0, 1)
    rho2 : float density of the solvent (water), kg/m^3
    E : float    Young's modulus, Pa
    T : float    absolute temperature, K
    F : float    Faraday constant, C/mol
    R : float    gas constant, J/(mol K)
    D : float    diffusion coefficient of the cations in the liquid phase, m^2/s (not in the
                 paper, which names it in its Nernst law but gives no value; used only by the
                 dynamic models).  Default :data:`D_CATION_DEFAULT`, source
                 :data:`D_CATION_SOURCE`.
    strain_limit : float   face strain ``e|kappa|`` up to which the small-strain beam model is
                 assumed (a model assumption: above it results are kept and flagged), in
                 (0, 1); default ``settings.STRAIN_LIMIT``, source ``settings.STRAIN_LIMIT_SOURCE``
    sheet_resistance : float  sheet (surface) resistance of each electrode, Ohm/sq, >= 0 (not in
                 the paper; 0 = ideal electrodes; used only by
                 :func:`ipmc_asym.dynamics.line.line_response`; source
                 :data:`SHEET_RESISTANCE_SOURCE`).
    v1, v2 : float   partial molar volumes of the cation and the water, m^3/mol (pressure term of
                 eq. (5) only; sources :data:`V1_LI_SOURCE`, :data:`V2_WATER_SOURCE`)
    M1, M2 : float   molar masses of the cation and the water, kg/mol (source :data:`M_SOURCE`)
    electrode : Electrode  metal layers on the faces (:mod:`ipmc_asym.model.electrode`); default
                 none (the paper's bare membrane); they change the beam (stiffness, mass), never the
                 electrochemistry
    """

    Z3: float = -9.0e4
    rho3: float = 2078.0
    phi4: float = 0.38
    rho2: float = 1000.0
    E: float = 1.3e8
    T: float = 300.0
    F: float = 96487.0
    R: float = 8.31
    D: float = D_CATION_DEFAULT
    c_moy: object = "paper"
    sheet_resistance: float = 0.0
    v1: float = V1_LI_DEFAULT
    v2: float = 18.0154e-3 / 1000.0
    M1: float = 6.941e-3
    M2: float = 18.0154e-3
    name: str = "nafion-li"
    #: full citations of the sources of the values (a material set's; :data:`NAFION_LI` carries
    #: the paper's)
    sources: tuple = ()
    strain_limit: float = STRAIN_LIMIT
    electrode: Electrode = NO_ELECTRODE

    def __post_init__(self):
        if not isinstance(self.electrode, Electrode):
            raise ValueError(f"electrode must be an Electrode (ipmc_asym.model.electrode); got {self.electrode!r}")
        z3 = check_finite("Z3", self.Z3, "a finite number < 0 C/kg")
        if z3 >= 0.0:
            raise ValueError(f"Z3 must be a finite number < 0 C/kg (fixed anions); got {self.Z3!r}")
        check_positive("rho3", self.rho3, "kg/m^3")
        phi4 = check_finite("phi4", self.phi4, "in the open interval (0, 1)")
        if not 0.0 < phi4 < 1.0:
            raise ValueError(f"phi4 must be in the open interval (0, 1); got {self.phi4!r}")
        check_positive("rho2", self.rho2, "kg/m^3")
        check_positive("modulus E", self.E, "Pa")
        check_positive("temperature T", self.T, "K")
        check_positive("Faraday constant F", self.F, "C/mol")
        check_positive("gas constant R", self.R, "J/(mol K)")
        check_diffusion(self.D)
        sl = check_finite("strain_limit", self.strain_limit, "in the open interval (0, 1)")
        if not 0.0 < sl < 1.0:
            raise ValueError(f"strain_limit must be in the open interval (0, 1), e.g. 0.01; got {self.strain_limit!r}")
        check_sheet_resistance(self.sheet_resistance)
        check_finite("v1", self.v1, "a finite number of m^3/mol")
        check_positive("v2", self.v2, "m^3/mol")
        check_positive("M1", self.M1, "kg/mol")
        check_positive("M2", self.M2, "kg/mol")
        if isinstance(self.c_moy, str):
            if self.c_moy not in ("paper", "formula"):
                raise ValueError(
                    f"c_moy must be 'paper', 'formula' or a number > 0 mol/m^3; got {self.c_moy!r}"
                )
        else:
            check_c_moy(self.c_moy)
        if self.c_moy == "formula":  # eq. (17) from phi4, rho3 and Z3, each accepted on its own
            check_c_moy(self.C_moy_formula, "C_moy (formula, eq. (17) from phi4, rho3 and Z3)")

    @property
    def C_moy_formula(self) -> float:
        """``-(1 - phi4) rho3 Z3 / (phi4 F)`` (paper section 4), mol/m^3."""
        return -(1.0 - self.phi4) * self.rho3 * self.Z3 / (self.phi4 * self.F)

    @property
    def C_moy(self) -> float:
        """Mean cation concentration used by the model, mol/m^3."""
        if self.c_moy == "paper":
            return C_MOY_PAPER
        if self.c_moy == "formula":
            return self.C_moy_formula
        return float(self.c_moy)

    def with_(self, **kw) -> "Material":
        return replace(self, **kw)

    @classmethod
    def from_file(cls, path) -> "Material":
        """A user's material file (TOML, the schema of ``ipmc_asym/materials/*.toml``, units accepted).

        A parameter the file does not give falls back visibly to :data:`FALLBACK_DEFAULTS`
        (``ipmc-asym materials FILE.toml`` lists it as such); ``Z3`` (or ``IEC``), ``rho3``,
        ``phi4`` and ``E`` are required.

        Raises
        ------
        ValueError
            One line naming the file and the key.
        """
        return cls(**material_data.read_set(path, FALLBACK_DEFAULTS).material_kwargs())

    @classmethod
    def named(cls, name: str) -> "Material":
        """A built-in material set (``ipmc_asym/materials/NAME.toml``)."""
        return cls(**material_data.load_set(name, FALLBACK_DEFAULTS).material_kwargs())


#: the sources of the paper's set (``ipmc_asym/materials/nafion-li.toml``; a test keeps them equal)
PAPER_CITATION = ("M. Tixier, J. Pouget, Validation d'un modèle pour un polymère électroactif (in French; conference "
                  "paper: static model of an IPMC strip, sections 3-6), Université de Versailles Saint-Quentin and "
                  "Sorbonne Université, Institut Jean le Rond d'Alembert")
D_CITATION = ("ipmc_asym default cation diffusion coefficient D = 1e-10 m^2/s (params.D_CATION_SOURCE): an "
              "assumption, not a measured value for Li+ in Nafion (no source read gives one); not a value of this "
              "set's source")
#: what a parameter a material file does not give falls back to: (value SI, full citation);
#: the values of the paper's set (``nafion-li``)
FALLBACK_DEFAULTS = {
    "rho2": (1000.0, PAPER_CITATION),
    "T": (300.0, PAPER_CITATION),
    "F": (96487.0, PAPER_CITATION),
    "R": (8.31, PAPER_CITATION),
    "D": (D_CATION_DEFAULT, D_CITATION),
}


NAFION_LI = Material(sources=(PAPER_CITATION, D_CITATION))
#: the sets with the paper's data, for which ``c_moy = "paper"`` (3082 mol/m^3) is meaningful
_PAPER_SETS = ("nafion-li", "nafion-li-formula")
MATERIALS = {"nafion-li": NAFION_LI}

#: keys of a material specification (scene ``[material]`` table, CLI options)
MATERIAL_KEYS = ("preset", "E", "modulus", "c_moy", "phi4", "Z3", "rho3", "rho2", "T", "strain_limit", "electrode",
                 "electrode_thickness", "electrode_metal", "electrode_modulus", "electrode_density")
#: flat keys of a material specification -> key of the electrode table (``[electrode]``)
ELECTRODE_SPEC_KEYS = {"electrode_thickness": "thickness", "electrode_metal": "metal",
                       "electrode_modulus": "modulus", "electrode_density": "density"}


def material_from_spec(spec=None, labels=None) -> Material:
    """The one material parser (scene ``[material]`` tables and the command line).

    Parameters
    ----------
    spec : dict or None
        Any of :data:`MATERIAL_KEYS`: ``preset`` (a built-in set name, default ``nafion-li``,
        or a user's material file ``FILE.toml``: :func:`named_material`); ``E`` or ``modulus`` (Pa, number or string with units such as
        ``"130MPa"``); ``c_moy`` (``"paper"``, ``"formula"``, or a number > 0 in mol/m^3,
        also as a string); ``phi4``, ``Z3``, ``rho3``, ``rho2``, ``T``, ``strain_limit`` (numbers, SI).
    labels : dict, optional
        How to name each key in error messages (e.g. ``{"c_moy": "--c-moy"}``); default
        ``material.<key>``.

    Returns
    -------
    Material

    Raises
    ------
    ValueError
        One line naming the key: unknown key, wrong type, value out of range.
    """
    spec = {} if spec is None else spec
    labels = labels or {}

    def name(k):
        return labels.get(k, f"material.{k}")

    if not isinstance(spec, dict):
        raise ValueError(f"material must be a table (section); got {type(spec).__name__}")
    for k in spec:
        if k not in MATERIAL_KEYS:
            raise ValueError(f"unknown key {k!r} in [material]; allowed: {', '.join(sorted(MATERIAL_KEYS))}")
    preset = spec.get("preset", "nafion-li")
    if isinstance(preset, Material):
        base = preset
    else:
        try:
            base = named_material(preset)
        except ValueError as exc:
            raise ValueError(f"{name('preset')}: {exc}") from None
    if "E" in spec and "modulus" in spec:
        raise ValueError(f"{name('E')}: give E or modulus, not both")
    kw = {}
    # the layers on the set's membrane first: they are the set's own kind of data, the numbers
    # below are plain values
    if "electrode" in spec and not isinstance(spec["electrode"], dict):
        raise ValueError(f"{name('electrode')} must be a table (thickness, metal, modulus, density)")
    el = dict(spec.get("electrode") or {})
    el.update({ELECTRODE_SPEC_KEYS[k]: spec[k] for k in ELECTRODE_SPEC_KEYS if k in spec})
    el_labels = {ELECTRODE_SPEC_KEYS[k]: name(k) for k in ELECTRODE_SPEC_KEYS}
    if el:
        kw["electrode"] = electrode_from_spec(el, el_labels, base.electrode)
    for k in ("E", "modulus"):
        if k in spec:
            v = spec[k]
            if isinstance(v, bool) or not isinstance(v, (int, float, str)):
                raise ValueError(f"{name(k)} must be a number or a string with units; got {v!r}")
            E = parse_pressure(name(k), v)
            if E <= 0:
                raise ValueError(f"{name(k)} must be > 0 Pa (e.g. 130MPa); got {v!r}")
            kw["E"] = E
    for k in ("phi4", "Z3", "rho3", "rho2", "T", "strain_limit"):
        if k in spec:
            v = spec[k]
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise ValueError(f"{name(k)} must be a number; got {v!r}")
            kw[k] = float(v)
    if "c_moy" in spec:
        v = spec["c_moy"]
        bad = f"{name('c_moy')} must be paper, formula or a number > 0 mol/m^3; got {v!r}"
        if isinstance(v, bool) or not isinstance(v, (int, float, str)):
            raise ValueError(bad)
        if isinstance(v, str) and v not in ("paper", "formula"):
            try:
                v = float(v)
            except ValueError:
                raise ValueError(bad) from None
        if not isinstance(v, str) and not (math.isfinite(v) and v > 0):
            raise ValueError(bad)
        if not isinstance(v, str):
            check_c_moy(v, name("c_moy"))
        if v == "paper" and base.name not in _PAPER_SETS:  # 3082 is the paper's Nafion Li+ value
            raise ValueError(f"{name('c_moy')} = paper is the C_moy the paper states for its Nafion Li+; the material "
                             f"{base.name} takes formula (eq. (17) from its own data) or a number in mol/m^3")
        kw["c_moy"] = v
    try:
        given = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in kw.items()
                          if k != "electrode")
        if given:  # the bibliography says which values are not from the set's sources
            kw["sources"] = tuple(base.sources) + (f"given by the user, not from these sources: {given}",)
        if "electrode" in kw and kw["electrode"].present and kw["electrode"].source:
            kw["sources"] = tuple(kw.get("sources", base.sources)) + (f"electrode layers: {kw['electrode'].source}",)
        return base.with_(**kw)
    except ValueError as exc:
        raise ValueError(f"material: {exc}") from None


def named_material(spec) -> Material:
    """A material from a name: ``nafion-li`` (:data:`NAFION_LI`), another built-in set
    (``ipmc_asym/materials/NAME.toml``) or a user's file ``FILE.toml``."""
    if not isinstance(spec, str) or not spec.strip():
        raise ValueError(f"material must be a set name or a file NAME.toml; got {spec!r}")
    if spec in MATERIALS:
        return MATERIALS[spec]
    if spec.endswith(".toml"):
        return Material.from_file(spec)
    return Material.named(spec)


def set_thickness(spec):
    """The typical TOTAL membrane thickness a material set states, ``(value m, note)``, or None.

    ``spec``: a set name or a file ``NAME.toml`` (as :func:`named_material`).  The paper's set
    ``nafion-li`` states none (the strip's default 200 µm stays).  The note names the set, the
    value and where the source gives it, for the output to say so.
    """
    if not isinstance(spec, str) or spec in MATERIALS:
        return None
    s = (material_data.read_set if spec.endswith(".toml") else material_data.load_set)(spec, FALLBACK_DEFAULTS)
    p = s.parameters.get("thickness")
    if p is None:
        return None
    return p.value, (f"thickness {p.value * 1e6:.4g} um: the typical thickness of material set {s.name} "
                     f"({p.where or p.source}); --thickness to change it")


@dataclass(frozen=True)
class Strip:
    """Cantilever strip.  ``width`` and ``thickness`` are TOTAL (2l, 2e); SI units, or strings
    with units (``Strip(thickness="200um", voltage="500mV")``), kept as SI floats.

    ``voltage`` may be negative (mirror image) or zero (no bending).
    """

    length: float = 0.02
    width: float = 5.0e-3
    thickness: float = 200.0e-6
    voltage: float = 1.0

    def __post_init__(self):
        # the units people write, at the edge (as the command line and moment_integral take them)
        for name, parse in (("length", parse_length), ("width", parse_length), ("thickness", parse_length),
                            ("voltage", parse_voltage)):
            if isinstance(getattr(self, name), str):
                object.__setattr__(self, name, parse(name, getattr(self, name)))
        check_dimension("length", self.length)
        check_dimension("width (total, 2l)", self.width)
        check_dimension("thickness (total, 2e)", self.thickness, floor=False)
        check_min_thickness(self.thickness)  # a Strip is checked once, here: its users trust it
        check_voltage_cap(check_finite("voltage", self.voltage, "a finite number of volts"))

    @property
    def e(self) -> float:
        """Half thickness (the paper's ``e``), m."""
        return 0.5 * self.thickness

    @property
    def l(self) -> float:  # noqa: E743 - the paper's name
        """Half width (the paper's ``l``), m."""
        return 0.5 * self.width

    @property
    def I_p(self) -> float:
        """Second moment of area ``4 l e^3 / 3`` (paper section 3), m^4."""
        return float(second_moment(self.width, self.thickness))

    def with_(self, **kw) -> "Strip":
        return replace(self, **kw)


NOMINAL_STRIP = Strip()


def bending_stiffness(material: Material, width, thickness, modulus=None):
    """Bending stiffness of the strip (N m^2), vectorised over TOTAL width and thickness (m).

    The bare membrane ``E I_p`` (paper section 3) or, with ``material.electrode``, the symmetric
    three-layer section (:func:`ipmc_asym.model.electrode.composite_stiffness`); ``modulus``
    (Pa, per point) replaces the membrane's ``material.E``.
    """
    E = material.E if modulus is None else modulus
    return composite_stiffness(E, width, thickness, material.electrode)


def second_moment(width, thickness):
    """``I_p = 4 l e^3 / 3`` (m^4) from TOTAL width and thickness (vectorised)."""

    l = 0.5 * np.asarray(width, dtype=float)  # noqa: E741
    e = 0.5 * np.asarray(thickness, dtype=float)
    return 4.0 * l * e**3 / 3.0


def as_material(material, what: str = "material") -> Material:
    """The material of a public function's ``material`` argument: a :class:`Material`, a set name
    or file (``"nafion-li"``, ``"FILE.toml"``, :func:`named_material`), a ``[material]`` table
    (dict, :func:`material_from_spec`) or None (``nafion-li``); one-line ``ValueError`` otherwise."""
    if material is None:
        return NAFION_LI
    if isinstance(material, Material):
        return material
    if isinstance(material, str):
        return named_material(material)
    if isinstance(material, dict):
        return material_from_spec(material)
    raise ValueError(f"{what} must be a Material, a set name (e.g. 'nafion-li', see ipmc_asym.materials()) or a "
                     f"[material] table; got {type(material).__name__}")


def as_strip(strip, what: str = "strip") -> Strip:
    """``strip`` if it is a :class:`Strip`; one-line ``ValueError`` otherwise."""
    if isinstance(strip, Strip):
        return strip
    raise ValueError(f"{what} must be an ipmc_asym.Strip, e.g. Strip(length=0.02, width=5e-3, thickness=200e-6, "
                     f"voltage=1.0); got {type(strip).__name__}")
