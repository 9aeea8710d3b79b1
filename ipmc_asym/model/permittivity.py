"""Permittivity models ``eps(C)`` (paper section 4; docs/design.md).

``eps = eps0 + (eps_moy - eps0) C / C_moy``; in dimensionless form
``eps_bar = A0 C_bar + A1``.  The paper writes ``alpha = 1e-3 F/m``; the numbers it quotes
(``z0 = sqrt(A0/A2) ~ 4.8e-3``) only fit ``eps_moy - eps0 = 1e-3 F/m``, which is what
``deps`` holds here.

A user-supplied callable ``eps(C)`` (SI: mol/m^3 -> F/m) is accepted by the BVP path only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional

from ipmc_asym.base.registry import MODELS as _REGISTRY
from ipmc_asym.model.params import Groups, Material, Strip, check_finite, make_groups

__all__ = ["MODELS", "Permittivity", "get_model"]


@dataclass(frozen=True)
class Permittivity:
    """``eps(C) = eps0 + deps * C / C_moy`` (F/m), or a custom callable.

    Attributes
    ----------
    name : str
    eps0 : float   permittivity at C = 0, F/m
    deps : float   eps_moy - eps0, F/m
    func : callable or None
        Custom ``eps(C)`` (C in mol/m^3, returns F/m); only the ``bvp`` fidelity uses it.
    """

    name: str
    eps0: float = 0.0
    deps: float = 0.0
    func: Optional[Callable] = None

    def __post_init__(self):
        if self.func is None:
            e0 = check_finite("eps0", self.eps0, "a finite number >= 0 F/m")
            de = check_finite("eps_moy - eps0", self.deps, "a finite number >= 0 F/m")
            if e0 < 0 or de < 0 or (e0 == 0 and de == 0):
                raise ValueError(
                    "permittivity needs eps0 >= 0 and eps_moy - eps0 >= 0 F/m, not both zero; "
                    f"got eps0={self.eps0!r}, eps_moy-eps0={self.deps!r}"
                )
        elif not callable(self.func):
            raise ValueError(f"permittivity func must be callable eps(C) -> F/m; got {self.func!r}")

    @property
    def is_custom(self) -> bool:
        return self.func is not None

    @property
    def eps_moy(self) -> float:
        return self.eps0 + self.deps

    def groups(self, strip: Strip, material: Material) -> Groups:
        """Dimensionless groups (``A0`` from ``deps``, ``A1`` from ``eps0``).

        For a custom ``eps(C)``, ``A0``/``A1`` describe the secant through ``C = 0`` and
        ``C = C_moy`` (used only for initial guesses and the layer-thickness estimate).
        """
        if self.func is None:
            return make_groups(strip, material, self.eps0, self.deps)
        return make_groups(strip, material, *self.secant(material.C_moy))

    def secant(self, C_moy: float) -> tuple:
        """``(eps0, deps)`` (F/m) of the affine law through ``eps(0)`` and ``eps(C_moy)``.

        For an affine model these are its own ``eps0, deps``; for a custom ``eps(C)`` the
        secant through ``C = 0`` and ``C = C_moy`` (``C_moy`` in mol/m^3), each clipped at 0.
        """
        if self.func is None:
            return self.eps0, self.deps
        e0 = max(float(self.func(0.0)), 0.0)
        return e0, max(float(self.func(C_moy)) - e0, 0.0)


#: The paper's three models (section 4 table), SI (F/m), from the registry.
MODELS = {name: Permittivity(name, eps0=spec.eps0, deps=spec.deps) for name, spec in _REGISTRY.items()}


def get_model(model) -> Permittivity:
    """Return a :class:`Permittivity` from a name, a ``Permittivity`` or a callable ``eps(C)``."""
    if isinstance(model, Permittivity):
        return model
    if isinstance(model, str):
        try:
            return MODELS[model]
        except KeyError:
            raise ValueError(
                f"model must be one of {', '.join(MODELS)}; got {model!r}"
            ) from None
    if callable(model):
        return Permittivity("custom", func=model)
    raise ValueError(f"model must be one of {', '.join(MODELS)} or a callable eps(C); got {model!r}")
