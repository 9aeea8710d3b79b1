"""The one fidelity ladder: climb rungs, cheapest first, until each point has a valid one.

Every escalation of the package goes through :func:`climb`: the moment integral
(:func:`ipmc_asym.forward.escalation.moment_escalating`), its per-point ``C_moy`` form and its
pressure-term form (:mod:`ipmc_asym.forward`), the electrode charge
(:func:`ipmc_asym.integral.charge.charge_escalated`) and the time-domain switch from the
reduced circuit to the PNP solver (:func:`ipmc_asym.dynamics.circuit.step_response`).  What a
rung is and what makes it valid stays with the caller (``evaluate`` and ``checks``); the order,
the bookkeeping of which points are left and the wording of the reasons live here.

Pure Python and NumPy: the base layer, reachable by every user.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["climb", "Ladder", "Step", "SkipRung", "rungs_from", "escalation_note", "first_shown"]


class SkipRung(ValueError):
    """Raised by ``evaluate``: the rung does not apply to these points (the message says why);
    the climb goes on to the next rung with the same points."""


def rungs_from(names, first: str, escalate: bool = True) -> tuple:
    """The rungs climbed from ``first``: ``names`` from ``first`` on, or ``(first,)`` alone."""
    names = tuple(names)
    return names[names.index(first):] if escalate else (first,)


def escalation_note(frm: str, to: str, why: str) -> str:
    """One line: the climb left rung ``frm`` for ``to`` because of ``why``."""
    return f"fidelity escalated {frm} -> {to}: {why}"


@dataclass
class Step:
    """One rung evaluated: ``rung`` at the flat points ``idx``, its ``result`` and where it is valid
    (``ok``, bool array over ``idx``)."""

    rung: str
    idx: np.ndarray
    result: object
    ok: np.ndarray


@dataclass
class Ladder:
    """What :func:`climb` returns.

    Attributes
    ----------
    steps : list of Step   every rung evaluated, in order
    left : ndarray of int   flat points where no rung is valid
    why : list of str   ``"rung: reason"`` of each rung that failed somewhere (or was skipped)
    n : int   number of points
    """

    steps: list
    left: np.ndarray
    why: list = field(default_factory=list)
    n: int = 1

    @property
    def valid(self) -> np.ndarray:
        """Bool array over the ``n`` points: a rung is valid there."""
        v = np.ones(self.n, bool)
        v[self.left] = False
        return v

    @property
    def last(self) -> Step | None:
        """The last rung evaluated (None if every rung was skipped)."""
        return self.steps[-1] if self.steps else None

    def used(self) -> np.ndarray:
        """Per point: the rung whose value is kept ("" where none)."""
        out = np.full(self.n, "", dtype=f"U{max([len(s.rung) for s in self.steps] + [1])}")
        for s in self.steps:
            out[s.idx[s.ok]] = s.rung
        return out

    def message(self, where: str, *, what: str = "", keep: int = 3) -> str:
        """One line: why the first point left has no valid rung ("" if none is left).

        ``where`` names that point (its inputs), ``what`` qualifies the ladder (e.g. "with the
        pressure term"); the reasons of the last ``keep`` failed rungs follow."""
        if self.left.size == 0:
            return ""
        head = "no valid fidelity" + (f" {what}" if what else "") + f" at {where}"
        return head + first_shown(self.left.size, self.n) + ": " + "; ".join(self.why[-keep:])


def first_shown(k: int, n: int) -> str:
    """``" [k of n points; first shown]"``: appended to a message about the first of ``k``
    points (of ``n``) that fail a check; empty for a single point."""
    return "" if n == 1 else f" [{k} of {n} points; first shown]"


def climb(rungs, evaluate, checks, n: int = 1) -> Ladder:
    """Climb ``rungs`` (cheapest first) over ``n`` points until each has a valid rung.

    Parameters
    ----------
    rungs : sequence of str
        The rungs tried, in order (:func:`rungs_from`).
    evaluate : callable ``(rung, idx) -> result``
        The rung at the flat points ``idx`` (int array; the points still without a valid rung).
        Raise :class:`SkipRung` where the rung does not apply (its message is the reason).
    checks : callable ``(rung, result, idx) -> (ok, reason)``
        ``ok``: bool (array over ``idx``, or a scalar for all of them), where the rung's value is
        valid; ``reason``: one phrase, why it is not at the first invalid point ("" if it is
        everywhere).  May raise to stop the climb (no rung can help).
    n : int
        Number of points (1: one point, or one indivisible result such as a time series).

    Returns
    -------
    Ladder
    """
    left = np.arange(int(n))
    steps, why = [], []
    for f in rungs:
        if left.size == 0:
            break
        try:
            r = evaluate(f, left)
        except SkipRung as exc:
            why.append(f"{f}: {exc}")
            continue
        ok, reason = checks(f, r, left)
        ok = np.broadcast_to(np.asarray(ok, bool), left.shape)
        steps.append(Step(f, left, r, ok))
        if not bool(np.all(ok)):
            why.append(f"{f}: {reason}" if reason else f"{f}: not valid")
        left = left[~ok]
    return Ladder(steps, left, why, int(n))
