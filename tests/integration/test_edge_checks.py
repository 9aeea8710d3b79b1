"""Checks once, at the edge: one estimate point validates each input once below the CLI.

Counted with cProfile (by code object, so a function imported under another name or module
is still the one counted): the thickness floor (``check_min_thickness``), the fidelity
(``check_fidelity``) and the model (``get_model``).
"""

import cProfile
import pstats

import ipmc_asym as ia
from ipmc_asym.cli import main
from ipmc_asym.model.params import Strip, check_min_thickness
from ipmc_asym.model.permittivity import get_model
from ipmc_asym.model.request import Request, check_fidelity

COUNTED = {"check_min_thickness": check_min_thickness, "check_fidelity": check_fidelity, "get_model": get_model}


def _calls(fn):
    """``{name: (calls, callers)}`` of the counted functions while ``fn()`` runs."""
    pr = cProfile.Profile()
    pr.enable()
    try:
        fn()
    finally:
        pr.disable()
    stats = pstats.Stats(pr).stats
    out = {}
    for name, f in COUNTED.items():
        code = f.__code__
        key = (code.co_filename, code.co_firstlineno, code.co_name)
        cc, nc, tt, ct, callers = stats.get(key, (0, 0, 0, 0, {}))
        out[name] = (nc, sorted(c[2] for c in callers))
    return out


def test_estimate_command_checks_each_input_once_below_the_cli(capsys):
    calls = _calls(lambda: main(["estimate", "--model", "constant", "--thickness", "200um", "--json"]))
    capsys.readouterr()
    n, callers = calls["check_min_thickness"]
    # the option's own check (cli/common.strip_from_args) plus the Strip's, nothing below it
    assert n == 2 and callers == ["__post_init__", "strip_from_args"], calls
    assert calls["check_fidelity"] == (1, ["__post_init__"]), calls
    assert calls["get_model"] == (1, ["__post_init__"]), calls


def test_evaluate_checks_each_input_once():
    strip = Strip(thickness=200e-6, voltage=1.0)  # built (and checked) outside the count
    calls = _calls(lambda: ia.evaluate(strip, "linear", "leading"))
    assert calls["check_min_thickness"][0] == 0, calls  # the Strip holds it
    assert calls["check_fidelity"] == (1, ["__post_init__"]), calls
    assert calls["get_model"] == (1, ["__post_init__"]), calls


def test_request_refuses_bad_input_in_one_line():
    import pytest

    for kw, word in (({"fidelity": "best"}, "fidelity"), ({"tol": 2.0}, "tol"), ({"model": "quadratic"}, "model")):
        with pytest.raises(ValueError, match=word) as exc:
            Request(**kw)
        assert "\n" not in str(exc.value)
    with pytest.raises(ValueError, match="MIN_THICKNESS"):
        Strip(thickness=50e-9)
    r = Request("affine", "exact", 0.01)
    assert r.model is get_model("affine") and r.limit == 0.01
