"""The Numba cache is keyed on every module that defines jitted code and what it imports."""

import re
from pathlib import Path

import ipmc_asym
import ipmc_asym.kernels.jit as _jit


def test_cache_key_covers_every_jitted_module():
    root = Path(ipmc_asym.__file__).parent
    jitted = {p.resolve() for p in root.rglob("*.py")
              if re.search(r"^@(jit|jit_parallel)\b", p.read_text(), re.M)}
    assert jitted, "no jitted modules found"
    assert jitted <= {p.resolve() for p in _jit.hashed_sources()}


def test_cache_key_covers_what_compiled_code_reaches():
    """Independent of the ``ast`` walk: at run time, every jitted function's module, and every
    package module or jitted function bound in that module's globals (what Numba may inline),
    is among the hashed sources."""
    import importlib
    import pkgutil
    import types

    root = Path(ipmc_asym.__file__).parent
    hashed = {p.resolve() for p in _jit.hashed_sources()}
    reached = set()
    for mod in pkgutil.walk_packages(ipmc_asym.__path__, "ipmc_asym."):
        if mod.name.startswith("ipmc_asym.cli") or mod.name.endswith("__main__"):
            continue
        m = importlib.import_module(mod.name)
        for f in vars(m).values():
            if not _jit._is_jitted(f) or not f.py_func.__module__.startswith("ipmc_asym."):
                continue
            g = f.py_func.__globals__
            reached.add(Path(g["__file__"]).resolve())
            for v in g.values():
                if isinstance(v, types.ModuleType) and v.__name__.startswith("ipmc_asym."):
                    reached.add(Path(v.__file__).resolve())
                elif _jit._is_jitted(v) and v.py_func.__module__.startswith("ipmc_asym."):
                    reached.add(Path(v.py_func.__globals__["__file__"]).resolve())
    assert any(p.parent.name != "kernels" for p in reached)  # integral/, io/, beam/ hold drivers too
    missing = sorted(str(p.relative_to(root)) for p in reached - hashed)
    assert missing == []


def test_memoised_source_list_is_the_computed_one(tmp_path):
    root = Path(ipmc_asym.__file__).resolve().parent
    fresh = _jit._memo_sources(root, str(tmp_path))  # computes and stores
    again = _jit._memo_sources(root, str(tmp_path))  # reads the stored list
    assert [p.resolve() for p in again] == [p.resolve() for p in fresh] == [p.resolve() for p in _jit.hashed_sources()]
    assert len(list(tmp_path.rglob("sources-*.txt"))) == 1


def test_flags_set_in_one_place():
    root = Path(ipmc_asym.__file__).parent
    offenders = [p.name for p in root.rglob("*.py") if p.resolve() != Path(_jit.__file__).resolve()
                 and re.search(r"numba\.(n)?jit\(|@(nb|numba)\.(n)?jit", p.read_text())]
    assert offenders == []


def test_import_leaves_the_users_numba_and_matplotlib_settings():
    """Importing the package, compiling a kernel and drawing a figure change no setting of
    the user's process: Numba's cache directory and matplotlib's backend stay as they were."""
    code = (
        "import matplotlib, numba; matplotlib.use('svg'); before = (numba.config.CACHE_DIR, matplotlib.get_backend());"
        "import ipmc_asym as ia, ipmc_asym.plotting as pl; ia.moment_integral(2e-4, 1.0, fidelity='leading');"
        "fig, ax = pl.pyplot().subplots(); ax.plot([0, 1]);"
        "after = (numba.config.CACHE_DIR, matplotlib.get_backend()); print(before == after, before, after)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("True"), out.stdout


def test_compiled_code_is_cached_in_the_package_cache_dir():
    """The per-function cache puts the compiled kernels under ``CACHE_DIR`` (not numba.config's)."""
    from ipmc_asym.kernels.closed import moment_closed

    assert moment_closed._cache._impl.locator.get_cache_path().startswith(_jit.CACHE_DIR)


def test_a_copy_of_the_package_elsewhere_shares_the_compiled_code(tmp_path):
    """Another install of the same sources (a site-packages copy beside a clone, say) computes the
    same cache directory and the same per-module folders, so it loads what this one compiled; a
    copy whose sources differ does not."""
    import shutil
    import subprocess
    import sys

    from ipmc_asym.kernels.closed import moment_closed

    src = Path(ipmc_asym.__file__).resolve().parent
    code = ("import ipmc_asym.kernels.jit as j, ipmc_asym.kernels.closed as c; "
            "print(c.moment_closed._cache._impl.locator.get_cache_path())")
    # the package's own cache location: a NUMBA_CACHE_DIR of the caller's (a CI's, say) names one
    # directory for every source and would make the edited copy's path the same by construction
    env = {k: v for k, v in __import__("os").environ.items() if k not in ("PYTHONPATH", "NUMBA_CACHE_DIR")}

    def cache_path(parent):
        env["PYTHONPATH"] = str(parent)
        p = subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp_path, capture_output=True, text=True,
                           timeout=120)
        assert p.returncode == 0, p.stderr
        return p.stdout.strip()

    def path_in_copy(edit=False):
        dst = tmp_path / ("edited" if edit else "same") / "ipmc_asym"
        shutil.copytree(src, dst, ignore=shutil.ignore_patterns("__pycache__"))
        if edit:
            with open(dst / "kernels" / "closed.py", "a", encoding="utf-8") as f:
                f.write("\n# an edit\n")
        return cache_path(dst.parent)

    here = cache_path(src.parent)
    if "NUMBA_CACHE_DIR" not in __import__("os").environ:
        assert here == moment_closed._cache._impl.locator.get_cache_path()
    assert path_in_copy() == here
    assert path_in_copy(edit=True) != here


def test_a_library_call_that_compiles_says_so_once(tmp_path):
    """A call that compiles (a fresh cache) writes one line on stderr before the compiler runs,
    once per process however many kernels compile; a call whose kernels load from the cache is
    silent."""
    import os
    import subprocess
    import sys

    code = ("import numpy as np; from ipmc_asym.kernels.bernoulli import bernoulli_point, bernoulli_array; "
            "bernoulli_point(0.5); bernoulli_array(np.ones(3))")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))

    def stderr():
        p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr
        return p.stderr

    first = stderr()
    assert first.count("compiling the Numba kernels") == 1 and "bernoulli_point" in first, first
    assert stderr() == ""


def test_the_command_line_notice_silences_the_library_s(monkeypatch, tmp_path, capsys):
    from ipmc_asym.cli.common import first_run_notice

    monkeypatch.setattr(_jit, "CACHE_DIR", str(tmp_path))  # an empty cache: the notice speaks
    monkeypatch.setitem(_jit._NOTICE, "given", False)
    first_run_notice()
    assert "compiling the Numba kernels" in capsys.readouterr().err
    assert _jit._NOTICE["given"]


# --------------------------------------------------------------------------------------
# Interpreted twins (start-up of one-shot commands): same source, same numbers
# --------------------------------------------------------------------------------------
import subprocess  # noqa: E402
import sys  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import ipmc_asym.integral.api as integral  # noqa: E402
from ipmc_asym.model.params import NAFION_LI  # noqa: E402
from ipmc_asym.model.permittivity import get_model  # noqa: E402


def _points(n, seed):
    rng = np.random.default_rng(seed)
    th = np.exp(rng.uniform(np.log(1e-6), np.log(1e-2), n))
    v = np.exp(rng.uniform(np.log(1e-4), np.log(20.0), n)) * rng.choice([-1.0, 1.0], n)
    v[:2] = 0.0, -0.0  # zero volts: the early return
    return th, v


@pytest.mark.parametrize("fidelity", ["leading", "corrected", "quadrature", "exact"])
@pytest.mark.parametrize("model", ["constant", "linear", "affine"])
def test_interpreted_driver_is_the_compiled_one_bit_for_bit(fidelity, model):
    """The twin runs the driver's own source in the interpreter: every output equal, bit for bit,
    to the compiled driver's (or the twin raises where the compiled code meets inf/NaN)."""
    n = 12 if fidelity == "exact" else 40
    th, v = _points(n, 3)
    consts = integral._driver_constants(get_model(model), NAFION_LI, fidelity)
    a = [np.empty(n) for _ in range(6)] + [np.empty(n, bool)]
    b = [np.empty(n) for _ in range(6)] + [np.empty(n, bool)]
    driver = integral._fused_driver(consts[5])
    driver(th, v, *consts, *a, False)
    try:
        with np.errstate(all="raise", under="ignore"):
            _jit.interpreted(driver)(th, v, *consts, *b, False)
    except (ArithmeticError, ValueError):
        pytest.skip("the interpreter met an inf/NaN the compiled code returns: the caller falls back")
    for x, y in zip(a, b):
        assert np.array_equal(x, y, equal_nan=True)


def test_interpreted_twins_call_twins_not_dispatchers():
    twin = _jit.interpreted(integral._fused_points)
    assert not _jit._is_jitted(twin)
    assert not _jit._is_jitted(twin.__globals__["_point"])
    assert _jit.interpreted(len) is len  # not jitted: itself


def test_estimate_interprets_a_few_points_and_loads_nothing_compiled():
    """``estimate`` (one-shot) runs its three points interpreted: no compiled driver is loaded
    (that load is what made start-up 2.6x ``import numba``); ``--compiled`` loads it; same output."""
    code = ("import sys; from ipmc_asym.cli import main; import ipmc_asym.integral.api as integral; "
            "rc = main(['estimate', '--fidelity', 'leading', '--json'] + sys.argv[1:]); "
            "sys.stderr.write('LOADED %d' % (len(integral._fused_blocks.signatures) "
            "+ len(integral._fused_points.signatures)))")
    out = {}
    for extra in ([], ["--compiled"]):
        p = subprocess.run([sys.executable, "-c", code, *extra], capture_output=True, text=True, timeout=600)
        assert p.returncode == 0, p.stderr
        out[bool(extra)] = (p.stdout, int(p.stderr.rsplit("LOADED", 1)[1]))
    assert out[False][1] == 0 and out[True][1] >= 1
    drop = re.compile(r'"seconds": [^,\n]*')  # wall times differ, nothing else may
    assert drop.sub("", out[False][0]) == drop.sub("", out[True][0])


def test_interpret_small_respects_the_budget(monkeypatch):
    """Twins only while points x interpreted cost <= ``settings.INTERPRET_BUDGET_S`` and the
    compiled driver is not loaded yet; never for a rung without an interpreted cost; the
    switch holds inside its ``with`` block only."""
    used = []
    monkeypatch.setattr(integral, "interpreted", lambda f: (lambda *a: used.append("twin")))

    class Driver:
        def __init__(self, signatures):
            self.signatures = signatures

        def __call__(self, *a):
            used.append("compiled")

    n_ok = int(integral.INTERPRET_BUDGET_S / integral._FIDELITY_SPECS["leading"].interpreted_s)
    with integral.interpret_small(False):  # whatever an earlier in-process command switched on
        with integral.interpret_small():
            integral._run_driver(Driver([]), n_ok, "leading", ())
            integral._run_driver(Driver([]), n_ok + 1, "leading", ())
            integral._run_driver(Driver(["loaded"]), 1, "leading", ())
            integral._run_driver(Driver([]), 1, "bvp", ())
        integral._run_driver(Driver([]), 1, "leading", ())  # outside the block: compiled
    assert used == ["twin", "compiled", "compiled", "compiled", "compiled"]
