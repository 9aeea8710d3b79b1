"""The one fidelity ladder (base/ladder.climb): its bookkeeping on a toy ladder whose answer is
known point by point, and that every escalation of the package climbs through it."""

import cProfile
import pstats

import numpy as np
import pytest

from ipmc_asym.base import ladder
from ipmc_asym.base.ladder import SkipRung, climb, rungs_from

RUNGS = ("a", "b", "c", "d")


def _toy(x, skip=()):
    """Rung k (0-based) is valid where x < k; rung names in ``skip`` do not apply."""
    seen = []

    def evaluate(f, idx):
        seen.append((f, idx.copy()))
        if f in skip:
            raise SkipRung("not here")
        return RUNGS.index(f)

    def checks(f, k, idx):
        ok = x[idx] < k
        return ok, "" if ok.all() else f"x = {x[idx][~ok][0]:g} >= {k}"

    return evaluate, checks, seen


def test_each_point_gets_its_cheapest_valid_rung():
    x = np.array([0.5, 2.5, -1.0, 9.0, 1.5])
    evaluate, checks, seen = _toy(x)
    lad = climb(RUNGS, evaluate, checks, x.size)
    # by hand: rung k holds where x < k, the first such k from 0
    assert list(lad.used()) == ["b", "d", "a", "", "c"]
    assert list(lad.valid) == [True, True, True, False, True]
    assert list(lad.left) == [3]
    # each rung saw only the points left by the previous ones
    assert [list(i) for _, i in seen] == [[0, 1, 2, 3, 4], [0, 1, 3, 4], [1, 3, 4], [1, 3]]
    assert lad.why == ["a: x = 0.5 >= 0", "b: x = 2.5 >= 1", "c: x = 2.5 >= 2", "d: x = 9 >= 3"]
    msg = lad.message("point 3")
    assert msg.startswith("no valid fidelity at point 3 [1 of 5 points; first shown]: ") and "\n" not in msg
    assert msg.endswith("b: x = 2.5 >= 1; c: x = 2.5 >= 2; d: x = 9 >= 3")


def test_skipped_rung_and_no_escalation():
    x = np.array([0.5, 1.5])
    evaluate, checks, seen = _toy(x, skip=("b",))
    lad = climb(RUNGS, evaluate, checks, 2)
    assert list(lad.used()) == ["c", "c"] and lad.why[1] == "b: not here"
    assert [s.rung for s in lad.steps] == ["a", "c"]
    assert rungs_from(RUNGS, "b") == ("b", "c", "d") and rungs_from(RUNGS, "b", escalate=False) == ("b",)
    lad = climb(rungs_from(RUNGS, "b", escalate=False), *_toy(x)[:2], 2)
    assert list(lad.used()) == ["b", ""] and lad.message("p", what="here").startswith("no valid fidelity here at p")


def test_checks_may_stop_the_climb():
    def checks(f, r, idx):
        raise ValueError("no rung helps")

    with pytest.raises(ValueError, match="no rung helps"):
        climb(RUNGS, lambda f, idx: 0, checks)


def _climbs(fn) -> int:
    """Calls of ``climb`` during a second ``fn()``: the first, unprofiled, compiles or loads the
    kernels it needs (Numba's compiler under the profiler is most of the cost otherwise)."""
    fn()
    pr = cProfile.Profile()
    pr.enable()
    try:
        fn()
    finally:
        pr.disable()
    code = ladder.climb.__code__
    return pstats.Stats(pr).stats.get((code.co_filename, code.co_firstlineno, code.co_name), (0, 0))[1]


def test_every_escalation_climbs_the_one_ladder():
    from ipmc_asym.dynamics.circuit import step_response
    from ipmc_asym.dynamics.electrode import charge_escalated
    from ipmc_asym.forward.escalation import moment_escalating
    from ipmc_asym.forward.model import forward
    from ipmc_asym.forward.pressure import moment_pressure_escalating
    from ipmc_asym.model.params import Strip

    cases = {
        "moment": lambda: moment_escalating([1e-6, 2e-4], 1.0, fidelity="leading"),
        "per-point c_moy": lambda: forward(0.02, 5e-3, 2e-4, 1.0, c_moy=[1000.0, 1200.0], fidelity="corrected"),
        "pressure term": lambda: moment_pressure_escalating(2e-4, 1.0),
        "charge": lambda: charge_escalated(1e-6, 2.0, fidelity="leading"),
        "circuit -> pnp": lambda: step_response(0.5, strip=Strip(), points=20),
    }
    for name, fn in cases.items():
        assert _climbs(fn) >= 1, name
