"""The output vocabulary: every input and output quantity with its unit, long name and, for
lengths across the strip, which thickness or width is meant.

One table (:data:`QUANTITIES`) that the text tables, CSV headers, JSON, NetCDF attributes and
plot labels read.  A quantity has its result-row name (``w``, ``F_block``, the keys of JSON
rows and CSV columns) and may have a scene-file name (``tip_deflection``, ``blocking_force``,
the names of scene and UQ outputs and of ``design`` specs); both name the same entry.
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["Quantity", "QUANTITIES", "BY_NAME", "quantity", "unit_and_long_name", "axis_label", "markdown_table"]


class Quantity(NamedTuple):
    """One quantity of the vocabulary.

    Attributes
    ----------
    name : str          result-row name (JSON key, CSV column, NetCDF variable)
    unit : str          SI unit ("1": dimensionless, "": no unit, e.g. a label)
    long_name : str     what it is, in words (NetCDF ``long_name``, plot labels)
    scene_name : str or None   name in scene files, UQ and design specs, where it has one
    extent : str or None       for a length across the strip: "total 2e", "total 2l" (never the half)
    """

    name: str
    unit: str
    long_name: str
    scene_name: str | None = None
    extent: str | None = None


QUANTITIES = (
    # inputs
    Quantity("length", "m", "strip length L"),
    Quantity("width", "m", "total width 2l", extent="total 2l"),
    Quantity("thickness", "m", "total thickness 2e", extent="total 2e"),
    Quantity("voltage", "V", "voltage phi0 (sign = bending direction)"),
    Quantity("modulus", "Pa", "Young's modulus E"),
    Quantity("c_moy", "mol/m^3", "mean cation concentration C_moy"),
    Quantity("eps0", "F/m", "permittivity eps0 of the cation-free polymer (eq. 16)"),
    Quantity("deps", "F/m", "permittivity increase eps_moy - eps0 (eq. 16)"),
    # outputs (paper eqs (6), (12)-(15), (27))
    Quantity("I", "1", "moment integral I (dimensionless)", scene_name="I"),
    Quantity("M_A", "N m", "bending moment M_A", scene_name="moment"),
    Quantity("theta", "rad", "free-end rotation theta", scene_name="rotation"),
    Quantity("w", "m", "tip deflection w (large displacement)", scene_name="tip_deflection"),
    Quantity("w_small", "m", "tip deflection w_p (small displacement)"),
    Quantity("x_tip", "m", "tip position along the clamp axis (large displacement)"),
    Quantity("y_tip", "m", "tip position across the clamp axis (large displacement)"),
    Quantity("x_line", "m", "centre line of the free strip, along the clamp axis"),
    Quantity("y_line", "m", "centre line of the free strip, across the clamp axis"),
    Quantity("F_block", "N", "blocking force F (large displacement)", scene_name="blocking_force"),
    Quantity("F_block_small", "N", "blocking force 3 M_A/(2 L) (small displacement)"),
    Quantity("B1", "1", "cathode concentration C(e)/C_moy"),
    Quantity("error", "1", "relative error estimate of I"),
    Quantity("error_estimate", "1", "relative error estimate of I"),
    Quantity("max_strain", "1", "largest bending strain e|kappa|"),
    Quantity("debye_length", "m", "Debye length of the neutral core"),
    # bookkeeping of a row
    Quantity("valid", "1", "every check passed (1) or not (0)"),
    Quantity("regime", "", "beam regime (small, large, past-quarter-turn, multi-turn)"),
    Quantity("fidelity_used", "", "fidelity the point was computed at (after escalation)"),
    Quantity("escalated", "1", "escalated above the requested fidelity (1) or not (0)"),
    Quantity("check_electrochemistry", "1", "check: a valid rung of the fidelity ladder (1) or none (0)"),
    Quantity("check_layer_separation", "1", "check: electrode layers separated by a neutral core"),
    Quantity("check_beam_regime", "1", "assumption: free strip within a quarter turn (values kept either way)"),
    Quantity("check_blocked_regime", "1", "assumption: blocked strip within a quarter turn (values kept either way)"),
    Quantity("check_strain", "1", "assumption: face strain within Material.strain_limit (values kept either way)"),
    Quantity("check_voltage", "1", "assumption: voltage magnitude within settings.VALIDATED_VOLTAGE (values kept either way)"),
    Quantity("check_slender", "1", "assumption: slender strip, model.limits.SLENDER_LIMITS (values kept either way)"),
    # fields of the result objects (base/results.py: summaries, plots, labelled datasets)
    Quantity("point", "1", "index of the point"),
    Quantity("small_error", "1", "relative deviation of w_small from w"),
    Quantity("block_error", "1", "relative deviation of F_block_small from F_block"),
    Quantity("core", "1", "neutral core left between the layers (units of e)"),
    Quantity("lam", "1", "core Debye length lambda/e"),
    Quantity("A2", "1", "group A2 = F phi0/(R T) (eq. 23)"),
    Quantity("z", "1", "position across the thickness z/e"),
    Quantity("C", "1", "cation concentration C/C_moy"),
    Quantity("phi", "1", "potential phi/|phi0|"),
    Quantity("E", "1", "electric field -dphi/dz (dimensionless, eq. 22)"),
    Quantity("D", "1", "electric induction D (dimensionless, eq. 22)"),
    Quantity("rhoZ", "1", "charge density C - 1 (dimensionless)"),
    Quantity("p", "1", "pressure p (dimensionless, B2 = 0)"),
    Quantity("sigma", "C/m^2", "surface charge of the face z = -e"),
    Quantity("Q", "C", "total charge of the electrode z = -e"),
    Quantity("C_diff", "F/m^2", "differential capacitance per area dsigma/dphi0"),
    Quantity("eps_app", "F/m", "apparent permittivity C_diff 2e"),
    Quantity("error_sigma", "1", "relative error estimate of sigma and Q"),
    Quantity("error_C_diff", "1", "relative error estimate of C_diff and eps_app"),
    Quantity("t", "s", "time"),
    Quantity("current_density", "A/m^2", "current density dsigma/dt"),
    Quantity("layer_voltage", "V", "voltage across the two electrode layers"),
    Quantity("sigma_error", "C/m^2", "error estimate of sigma"),
    Quantity("tau", "s", "linear time constant R C_d(0)"),
    Quantity("R", "Ohm m^2", "core resistance per area"),
    Quantity("C_d0", "F/m^2", "differential capacitance C_d(0) per area"),
    Quantity("f", "Hz", "frequency"),
    Quantity("f_d", "Hz", "dielectric relaxation frequency"),
    Quantity("Z", "Ohm", "impedance of the strip (electrode area 2l L)"),
    Quantity("Z_area", "Ohm m^2", "impedance per unit area"),
    Quantity("Z0", "Ohm", "characteristic impedance of the electrode line"),
    Quantity("H_w", "m/V", "tip deflection per volt (small displacements)"),
    Quantity("H_theta", "rad/V", "tip rotation per volt"),
    Quantity("H_F", "N/V", "blocking force per volt"),
    Quantity("H_M", "N m/V", "layers' moment per volt of local voltage"),
    Quantity("H_charge", "C/V", "electrode charge per volt (electrode area 2l L)"),
    Quantity("H_current", "A/V", "current per volt (electrode area 2l L)"),
    Quantity("w_amp", "m/V", "amplitude |H_w| of the tip deflection per volt"),
    Quantity("w_phase", "rad", "phase arg H_w of the tip deflection"),
    Quantity("gamma_L", "1", "propagation constant times length gamma L"),
    Quantity("error_Z", "1", "relative error of Z and H_w against the linearised PNP"),
    Quantity("beam_error", "1", "relative error estimate of the dynamic beam's transfers"),
    Quantity("sheet_resistance", "Ohm/sq", "sheet resistance R_s of each electrode"),
    Quantity("pole", "rad/s", "pole of the rational model"),
    Quantity("residue", "", "residue of the rational model (unit of the output times rad/s)"),
    Quantity("sample", "1", "index of the sample"),
    Quantity("count", "1", "number of samples in the bin"),
    Quantity("row", "1", "index of the data row"),
    Quantity("measured_deflection", "m", "measured tip deflection |w|"),
    Quantity("fitted_deflection", "m", "fitted model's tip deflection |w|"),
    Quantity("measured_blocking_force", "N", "measured blocking force |F|"),
    Quantity("fitted_blocking_force", "N", "fitted model's blocking force |F|"),
    Quantity("work", "N m", "work w F of the strip"),
    Quantity("first_resonance", "Hz", "first natural frequency of the free strip"),
    Quantity("footprint", "m^2", "footprint L 2l of the strip"),
    Quantity("diffusion", "m^2/s", "cation diffusion coefficient D"),
    Quantity("viscous_modulus", "Pa s", "viscous modulus of the strip (Kelvin-Voigt damping)"),
    # sensing (derivations/sensing.py)
    Quantity("curvature", "1/m", "imposed curvature kappa = w'' at the clamp (eps_xx = -kappa z)"),
    Quantity("tip_displacement", "m", "imposed tip displacement w (small displacement)"),
    Quantity("V_oc", "V", "open-circuit voltage phi(-e) - phi(e) of the relaxed bent strip"),
    Quantity("error_V_oc", "1", "relative error estimate of V_oc"),
    Quantity("Q_per_w", "C/m", "short-circuit charge per tip displacement Q/w"),
    Quantity("strain_parameter", "1", "b = (1 - 2 nu) kappa e/phi4 at the clamp: fixed-charge change at a face"),
    Quantity("nu", "1", "drained Poisson ratio of the membrane (assumption: no source read)"),
    # sensing in the frequency domain (derivations/sensing_dynamic.py)
    Quantity("I_per_w", "A/m", "short-circuit current per tip displacement"),
    Quantity("V_oc_per_w", "V/m", "open-circuit voltage per tip displacement"),
    Quantity("V_load", "V", "voltage across the resistive load at the tip amplitude"),
    Quantity("I_load", "A", "current through the resistive load at the tip amplitude"),
    Quantity("harvested_power", "W", "mean power into the resistive load at the tip amplitude"),
    Quantity("error_sensing", "1", "relative error of the sensing response against the exact linear form"),
    Quantity("one_way_error", "1", "estimate of the neglected pressure feedback on the strain"),
    Quantity("check_one_way", "1", "one-way coupling estimate within its bound"),
    Quantity("amplitude", "m", "peak tip displacement of the load columns"),
    Quantity("load_resistance", "Ohm", "resistance of the load across the electrodes"),
    Quantity("sensitivity", "C/m", "static short-circuit charge per tip displacement |Q/w| (design output)"),
    Quantity("emf", "V", "EMF of the bent strip in time (its open-circuit voltage phi(-e) - phi(e))"),
    Quantity("power_instant", "W", "instantaneous power into the load V I"),
    Quantity("error_settled", "1", "relative error of the relaxed rows of a sensing transient"),
    Quantity("f_top", "Hz", "highest frequency the time-domain error is evaluated to"),
    Quantity("f_stream", "Hz", "frequency 3 D/(2 pi e^2) where the streaming potential equals the static EMF"),
)

#: every name (result-row name and scene name) -> its quantity
BY_NAME = {**{q.name: q for q in QUANTITIES}, **{q.scene_name: q for q in QUANTITIES if q.scene_name}}


def quantity(name: str) -> Quantity:
    """The quantity called ``name`` (row or scene name); ``ValueError`` listing the names if unknown."""
    try:
        return BY_NAME[name]
    except KeyError:
        raise ValueError(f"unknown quantity {name!r}; known: {', '.join(BY_NAME)}") from None


def unit_and_long_name(name: str) -> tuple[str, str]:
    """``(unit, long_name)`` of ``name``; ``("", name)`` for a name outside the vocabulary."""
    q = BY_NAME.get(name)
    return (q.unit, q.long_name) if q else ("", name)


def axis_label(name: str, unit: str | None = None) -> str:
    """Plot label: long name and unit (``unit`` overrides the SI unit, e.g. "mm")."""
    u, ln = unit_and_long_name(name)
    u = u if unit is None else unit
    return ln if u in ("", "1") else f"{ln} [{u}]"


def markdown_table() -> str:
    """The vocabulary as a Markdown table (the one in ``docs/design.md``)."""
    lines = ["| name | scene name | unit | meaning |", "|---|---|---|---|"]
    for q in QUANTITIES:
        scene = f"`{q.scene_name}`" if q.scene_name else ""
        lines.append(f"| `{q.name}` | {scene} | {q.unit} | {q.long_name} |")
    return "\n".join(lines)
