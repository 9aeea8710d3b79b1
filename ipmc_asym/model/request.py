"""What the caller asks of the static chain, checked once: model, fidelity, tolerance, escalation.

A :class:`Request` is validated when it is built (one-line ``ValueError`` naming the
parameter), its model resolved to a :class:`~ipmc_asym.model.permittivity.Permittivity`;
the layers below the public entries (:func:`ipmc_asym.forward.estimate.evaluate`,
:func:`ipmc_asym.forward.model.forward`, :func:`ipmc_asym.forward.escalation.moment_escalating`)
take it and trust it, as they trust a :class:`~ipmc_asym.model.params.Strip` (geometry, the
thickness floor) and a :class:`~ipmc_asym.model.params.Material`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ipmc_asym.base.registry import check_choice, fidelity_names
from ipmc_asym.base.settings import VALIDITY_LIMIT
from ipmc_asym.model.permittivity import Permittivity, get_model

__all__ = ["Request", "check_fidelity", "check_tol"]


def check_fidelity(fidelity: str) -> str:
    """``fidelity`` if it names a rung of the registry, else a one-line ``ValueError`` listing them."""
    return check_choice("fidelity", fidelity, fidelity_names())


def check_tol(tol, what="tol"):
    """``tol`` if it is a relative tolerance in (0, 1), else a one-line ``ValueError``."""
    if tol is None:
        return None
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating)) or not math.isfinite(tol) \
            or not 0.0 < float(tol) < 1.0:
        raise ValueError(f"{what} must be a relative tolerance in (0, 1), e.g. 0.01 for 1 %; got {tol!r}")
    return float(tol)


@dataclass(frozen=True)
class Request:
    """A static evaluation request, validated when built.

    Attributes
    ----------
    model : Permittivity
        Resolved from a name, a ``Permittivity`` or a callable ``eps(C)``.
    fidelity : str
        The cheapest rung tried (a name of ``registry.FIDELITIES``).
    tol : float or None
        Relative accuracy required of ``I``, in (0, 1); None: ``settings.VALIDITY_LIMIT``.
    escalate : bool
        Climb from ``fidelity`` to the first valid rung (False: ``fidelity`` only).
    pressure_term : bool
        Keep the pressure term of the Nernst-Planck law (paper eq. (5)).
    """

    model: Permittivity | str = "constant"
    fidelity: str = "quadrature"
    tol: float | None = None
    escalate: bool = True
    pressure_term: bool = False

    def __post_init__(self):
        check_fidelity(self.fidelity)
        object.__setattr__(self, "tol", check_tol(self.tol))
        object.__setattr__(self, "model", get_model(self.model))
        object.__setattr__(self, "escalate", bool(self.escalate))
        object.__setattr__(self, "pressure_term", bool(self.pressure_term))

    def with_model(self, model: Permittivity) -> "Request":
        """This request for another, already resolved model (a :class:`Permittivity`): the rest
        was checked when this one was built, so nothing is checked again (the model-form spread
        evaluates one request over the paper's models)."""
        new = object.__new__(Request)
        for k in ("fidelity", "tol", "escalate", "pressure_term"):
            object.__setattr__(new, k, getattr(self, k))
        object.__setattr__(new, "model", model)
        return new

    @property
    def limit(self) -> float:
        """The error bound a rung must meet: ``min(tol, settings.VALIDITY_LIMIT)``."""
        return VALIDITY_LIMIT if self.tol is None else min(self.tol, VALIDITY_LIMIT)
