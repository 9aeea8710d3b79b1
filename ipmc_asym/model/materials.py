"""Named material sets with their sources (``ia.materials``).

The data are the TOML files of ``ipmc_asym/materials/`` (one per set; schema and loader in
:mod:`ipmc_asym.model.material_data`); a user's file of the same schema is read by
:meth:`ipmc_asym.model.params.Material.from_file`.  Every value carries the full citation of
the source it was read in; a value a set has no source for is a visible fallback.

>>> import ipmc_asym as ia
>>> ia.materials.names()                       # doctest: +SKIP
('nafion-li', 'nafion-li-formula')
>>> m = ia.materials.get("nafion-li-formula")  # a params.Material
>>> print(ia.materials.bibliography(m))        # doctest: +SKIP
"""

from __future__ import annotations

from ipmc_asym.model import material_data
from ipmc_asym.model.electrode import beam_label
from ipmc_asym.model.params import FALLBACK_DEFAULTS, NAFION_LI, Material, named_material

__all__ = ["names", "get", "info", "citations", "bibliography", "material_comments",
           "describe", "NOT_OFFERED", "MaterialSets", "MATERIAL_SETS"]

#: membranes asked for that are not offered, and why (no source read for them here)
NOT_OFFERED = (
    "Flemion, Aquivion, and Nafion 115/117/NRE-211/NRE-212 in the Li+, Na+, K+ forms: not offered -- no source "
    "read gives their Z3 (or IEC), rho3, phi4 and hydrated E; the H+ sets take phi4 from the paper. "
    "Write a material file (docs/materials.md: the template) with your membrane's values and citations",
)


def names() -> tuple:
    """Names of the built-in sets."""
    return material_data.set_names()


def get(name: str = "nafion-li") -> Material:
    """The :class:`~ipmc_asym.model.params.Material` of a built-in set or a file ``FILE.toml``.

    Raises
    ------
    ValueError
        Unknown name (the message lists the sets), or a bad file (one line naming the key).
    """
    return named_material(name)


def _set_of(material):
    """The :class:`~ipmc_asym.model.material_data.MaterialSet` a material comes from, or None."""
    if isinstance(material, str):
        if material.endswith(".toml"):
            return material_data.read_set(material, FALLBACK_DEFAULTS)
        return material_data.load_set(material, FALLBACK_DEFAULTS)
    if material.name in names():
        return material_data.load_set(material.name, FALLBACK_DEFAULTS)
    return None


def info(material) -> dict:
    """Everything about a set: every value with unit, source, range, fallback; the derived
    ``C_moy`` (stated and eq. (17)); the citations (JSON-ready).

    Parameters
    ----------
    material : str or Material
        A set name, a file ``FILE.toml`` or a material (whose values are reported as used).
    """
    m = get(material) if isinstance(material, str) else material
    s = _set_of(material)
    d = s.as_dict() if s is not None else {"name": m.name, "parameters": {}, "sources": []}
    d["used"] = {"Z3": m.Z3, "rho3": m.rho3, "phi4": m.phi4, "rho2": m.rho2, "E": m.E, "T": m.T, "F": m.F,
                 "R": m.R, "D": m.D, "C_moy": m.C_moy, "C_moy_formula": m.C_moy_formula,
                 "c_moy_source": m.c_moy if isinstance(m.c_moy, str) else "given"}
    if m.electrode.present:
        e = m.electrode
        d["used"]["electrode"] = {"thickness": e.thickness, "modulus": e.modulus, "density": e.density,
                                  "metal": e.metal, "source": e.source}
    d["sources"] = list(citations(m))
    return d


def citations(material: Material) -> tuple:
    """Full citations of the sources of a material's values (its set's, or the paper's for the
    defaults :data:`~ipmc_asym.model.params.NAFION_LI`)."""
    if material.sources:
        return tuple(material.sources)
    if material.name in names():
        return material_data.load_set(material.name, FALLBACK_DEFAULTS).citations()
    return ()


def bibliography(material: Material, title: str | None = None) -> str:
    """The bibliography of a run: the material set and the numbered citations, one per line."""
    cites = citations(material)
    head = title or f"material set: {material.name}"
    lines = [head]
    lines += [f"  [{i}] {c}" for i, c in enumerate(cites, 1)] or ["  (no source: values given by the user)"]
    return "\n".join(lines)


def describe(material) -> str:
    """Text of ``ipmc-asym materials NAME``: every value with its unit and source."""
    d = info(material)
    cites = d["sources"]
    idx = {c: i for i, c in enumerate(cites, 1)}
    out = [f"{d['name']}: {d.get('title', '')}".rstrip(": "), f"  origin: {d.get('origin', 'given')}"]
    for k in ("membrane", "cation"):
        if d.get(k):
            out.append(f"  {k}: {d[k]}")
    if d.get("description"):
        out.append("  " + " ".join(d["description"].split()))
    out.append("  parameters (SI; [n] = source below):")
    for k, p in d["parameters"].items():
        src = f"[{idx[p['source']]}]" if p["source"] in idx else "(no source)"
        extra = []
        if p["quoted_from"]:
            extra.append(f"quoting {p['quoted_from']}")
        if p["where"]:
            extra.append(p["where"])
        if p["range"]:
            extra.append(f"range {p['range'][0]:g}-{p['range'][1]:g}")
        if p["fallback"]:
            extra.append("FALLBACK (not from this set's own sources)")
        if p["note"]:
            extra.append(p["note"])
        out.append(f"    {k:6s} = {p['value']:<10.6g} {p['unit']:10s} {src} {'; '.join(extra)}")
    for model, p in d.get("permittivity", {}).items():
        out.append(f"    permittivity {model}: eps0 = {p['eps0']:g} F/m, eps_moy - eps0 = {p['deps']:g} F/m "
                   f"[{idx.get(p['source'], '?')}] {p['where']}")
    u = d["used"]
    out.append(f"  C_moy used = {u['C_moy']:.6g} mol/m^3 ({u['c_moy_source']}); "
               f"eq. (17) -(1 - phi4) rho3 Z3/(phi4 F) = {u['C_moy_formula']:.6g} mol/m^3")
    out.append("  sources:")
    out += [f"    [{i}] {c}" for i, c in enumerate(cites, 1)]
    return "\n".join(out)


def default() -> Material:
    """The default material (the paper's set, ``nafion-li``)."""
    return NAFION_LI


class MaterialSets:
    """``ia.materials``: the material sets (``names()``, ``get(name)``, ``info``, ``citations``,
    ``bibliography``, ``describe``); the functions of :mod:`ipmc_asym.model.materials`."""

    names = staticmethod(names)
    get = staticmethod(get)
    info = staticmethod(info)
    citations = staticmethod(citations)
    bibliography = staticmethod(bibliography)
    describe = staticmethod(describe)
    NOT_OFFERED = NOT_OFFERED

    def __repr__(self):
        return f"<material sets: {', '.join(names())}>"


#: the object ``ipmc_asym.materials`` names
MATERIAL_SETS = MaterialSets()


def material_comments(material) -> list:
    """Header comment lines of a result file: the material set, the beam when it carries electrode
    layers (the bare membrane is the paper's beam) and the numbered sources."""
    beam = [f"beam: {beam_label(material.electrode)}"] if material.electrode.present else []
    return [f"material set: {material.name}"] + beam + [f"source [{i}]: {c}"
                                                       for i, c in enumerate(material.sources, 1)]
