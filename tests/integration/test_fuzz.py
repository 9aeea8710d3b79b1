"""Every command, random input: one line and exit 2, or exit 0 with finite results; bounded memory.

Hypothesis draws argument lists for all 14 commands (``ipmc-asym --help``: the 13 of the
package and the ``bench`` plugin) from pools that mix valid values, units, bare numbers,
tiny and huge magnitudes, subnormals, NaN/inf spellings, empty strings and garbage, plus fit
CSV files and uq/scene TOML files with a UTF-8 BOM, huge sizes, extreme magnitudes and
missing columns.  Asserted for every run:

* no traceback, exit status 0 or 2 (``--help``: 0);
* on exit 0, no NaN or inf printed as a result (JSON has ``null`` with a note instead);
* on exit 2, one error line on stderr, the last; before it only warnings on other options;
* peak memory under 1 GB, of this run alone. An in-process run counts what it adds to the
  test worker's resident size (Linux ``/proc/self/clear_refs`` resets the peak, ``VmHWM`` reads
  it) on top of the peak of a fresh process that imports the same libraries: the worker's own
  size belongs to the test session (a full suite pushes it past 1 GB; an emulator's translated
  code adds more), not to the command. A subprocess run reads its child's own peak through a
  small launcher that starts only that child (``RUSAGE_CHILDREN`` there): a child forked straight
  from the worker counts the worker's pages wherever ``fork`` is not ``vfork`` (qemu-user).

The default run is short (in-process ``main([...])`` calls, derandomised; a few subprocess
runs); the ``slow`` profile draws many more examples.
"""

from __future__ import annotations

import contextlib
import functools
import io
import os
import re
import resource
import subprocess
import sys

import pytest
from references import REPO

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, example, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from ipmc_asym.cli import COMMANDS, main, plugin_commands  # noqa: E402

ROOT = str(REPO)
GB = 1024**3

#: a NaN or inf printed as a number (a word on its own, not part of "information", "infinite")
_NONFINITE = re.compile(r"(?<![A-Za-z_])[-+]?(nan|inf|infinity)(?![A-Za-z_])", re.IGNORECASE)

FAST = settings(max_examples=12, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture,
                                       HealthCheck.filter_too_much, HealthCheck.data_too_large])
#: the long profile is deterministic too: CI must not fail on a new random draw (explore with
#: ``pytest --hypothesis-seed=<n>`` and a ``settings(derandomize=False)`` of your own)
SLOW = settings(FAST, max_examples=200, derandomize=True)


def _reset_peak() -> bool:
    """Reset this process's peak resident size (Linux >= 4.0); False where it cannot be."""
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        return True
    except OSError:
        return False


def _status_bytes(field: str) -> int | None:
    """A size from ``/proc/self/status`` (``VmRSS``, ``VmHWM``) in bytes; None where there is none."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith(field + ":"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def _maxrss_bytes(who) -> int:
    r = resource.getrusage(who).ru_maxrss
    return r if sys.platform == "darwin" else r * 1024  # Linux: kB


#: the libraries a command may import, for the fresh process that the in-process runs add to
_LIBRARIES = "import ipmc_asym.cli, numba, numpy, scipy.optimize, scipy.integrate, matplotlib, xarray"


@functools.cache
def _fresh_base() -> int:
    """Peak resident size of a fresh interpreter that imports :data:`_LIBRARIES`."""
    rc, _, err, peak = _run_child([sys.executable, "-c", _LIBRARIES], {**os.environ, "PYTHONPATH": ROOT})
    assert rc == 0, err
    return peak


def run_cli(argv):
    """``main(argv)`` in this process: (status, stdout, stderr, peak bytes of the run alone);
    argparse's SystemExit is a status."""
    before = _status_bytes("VmRSS")
    reset = _reset_peak()
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main(list(argv))
        except SystemExit as exc:
            rc = exc.code if isinstance(exc.code, int) else 2
    hwm = _status_bytes("VmHWM")
    if reset and before is not None and hwm is not None:
        peak = _fresh_base() + max(0, hwm - before)
    else:  # no resettable peak here: the whole session's, an upper bound
        peak = _maxrss_bytes(resource.RUSAGE_SELF)
    return rc, out.getvalue(), err.getvalue(), peak


def check_outcome(argv, rc, out, err, peak):
    assert "Traceback" not in err and "Traceback" not in out, (argv, err[-2000:])
    assert rc in (0, 2), (argv, rc, err[-2000:])
    if rc == 2:
        lines = [ln for ln in err.splitlines() if ln.strip()]
        assert lines and "error" in lines[-1], (argv, err)
        assert len([ln for ln in lines if "error:" in ln]) == 1, (argv, err)
        # before the refusal, only warnings on other options (a line saying that work starts, or
        # what it will cost, would announce work that never runs)
        assert all("warning:" in ln for ln in lines[:-1]), (argv, err)
    elif "--help" not in argv and argv[0] != "derive":  # derive prints the derivation's prose (W0(-inf))
        bad = _NONFINITE.search(out)
        assert bad is None, (argv, out[max(0, bad.start() - 200):bad.end() + 100])
    assert peak < GB, (argv, peak)


# ---- value pools -------------------------------------------------------------------------
JUNK = ["", "abc", "nan", "inf", "-inf", "NaN", "1e400", "-0", "0", "1e-320", "5e-324", "--", "1,5", "1e9999",
        "\u00b5m", "1_000", " 1 ", "0x10"]
LENGTHS = ["2cm", "200um", "100nm", "50nm", "1m", "200", "1e-300", "1e300", "5e-324", "10mm", "2 cm", "-1cm"]
VOLTS = ["1V", "-1V", "0", "0V", "1e-200", "5e-324", "1e-7", "20V", "1e6V", "-19V", "1mV", "1kV"]
PRESSURES = ["130MPa", "1e8", "1Pa", "1e20", "0", "-1MPa", "1GPa"]
COUNTS = ["1", "2", "3", "10", "1e3", "1e9", "1e12", "0", "-1", "2.5", "1e400"]
FREQS = ["1Hz", "0.01Hz", "1kHz", "1MHz", "1e-300Hz", "1e300", "0", "-1Hz"]
TIMES = ["1ms", "0.2s", "1e-12s", "1e6s", "0", "-1s"]
MODELS = ["constant", "linear", "affine", "all", "nope"]
FIDS = ["leading", "corrected", "quadrature", "exact", "bvp", "rk4"]

STRIP = {"--length": LENGTHS, "--width": LENGTHS, "--thickness": LENGTHS, "--modulus": PRESSURES,
         "--c-moy": ["paper", "formula", "3000", "0", "-5", "1e30"]}


def values(pool):
    return st.sampled_from(pool) | st.sampled_from(JUNK)


def options(table, max_size=4):
    """A few ``[--opt, value]`` pairs (or flags) drawn from ``table`` (value pool or None for a flag)."""
    def pair(opt):
        pool = table[opt]
        return st.just([opt]) if pool is None else values(pool).map(lambda v: [opt, v])

    return st.lists(st.sampled_from(sorted(table)).flatmap(pair), max_size=max_size).map(
        lambda ps: [a for p in ps for a in p])


CHEAP = {
    "estimate": {**STRIP, "--voltage": VOLTS, "--model": MODELS, "--fidelity": ["leading", "corrected", "quadrature"],
                 "--tol": ["1%", "1e-3", "0", "1", "5"], "--json": None, "--no-escalate": None},
    "laws": {"--model": MODELS, "--json": None, "--latex": None},
    "charge": {**STRIP, "--voltage": VOLTS, "--model": MODELS, "--fidelity": ["leading", "corrected"], "--json": None},
    "step": {**STRIP, "--voltage": VOLTS, "--model": MODELS[:3], "--points": COUNTS, "--duration": TIMES,
             "--diffusion": ["1e-10m2/s", "1e-10", "1e10", "1e-30", "0"], "--json": None,
             "--tol": ["none", "NONE", "0", "2", "1e-9", "auto:1", "nan"]},
    "freq": {**STRIP, "--model": MODELS[:3], "--points": COUNTS, "--method": ["pnp-linear", "circuit", "x"],
             "--diffusion": ["1e-10m2/s", "1e-30", "1e10"], "--json": None},
    "sweep": {**STRIP, "--voltage": VOLTS, "--model": MODELS, "--fidelity": ["leading", "corrected"],
              "--max-rows": COUNTS, "--json": None, "--no-progress": None, "--spread": None},
    "materials": {"--json": None},
    "sense": {**STRIP, "--model": MODELS, "--fidelity": ["leading", "exact"], "--support": ["free", "tip-force", "x"],
              "--load": ["short", "open", "100"], "--nu": ["0", "0.3", "0.7"], "--json": None},
    "drive": {**STRIP, "--model": MODELS[:3], "--points": COUNTS, "--duration": TIMES,
              "--beam": ["quasi-static", "dynamic", "x"], "--json": None},
    # the layer summary only (no --out): one BVP per model, the cheaper models
    "profiles": {**STRIP, "--voltage": VOLTS, "--model": ["constant", "affine", "nope"], "--json": None},
}
MATERIAL_NAMES = ["nafion-li", "nafion-117-h", "nope", "/nonexistent.toml", "x.csv"]
WAVEFORMS = ["step:1V", "sine:1V@10Hz", "dc:0.2V+sine:0.5V@10Hz", "square:1V@5Hz", "ramp:1V/1s", "sine:1V@-1Hz",
             "step:1e300V", "csv:/nonexistent.csv", "nope:1V", ""]
SWEEP_VARY = ["voltage=1V:2V:3", "length=1cm:4cm:4", "thickness=10um:1mm:3:log", "voltage=1e-300:1e-200:3:log",
              "modulus=1MPa:1GPa:2", "length=1cm:2cm:1e9", "thickness=1:2", "voltage=0:0:1", "nope=1:2:3"]


@st.composite
def cheap_argv(draw):
    cmd = draw(st.sampled_from(sorted(CHEAP)))
    argv = [cmd] + draw(options(CHEAP[cmd]))
    if cmd == "sweep":
        argv += ["--vary", draw(st.sampled_from(SWEEP_VARY))]
    if cmd == "freq":
        argv += ["--from", draw(values(FREQS)), "--to", draw(values(FREQS))]
    if cmd in ("step", "freq") and "--points" not in argv:
        argv += ["--points", "20"]
    if cmd == "step" and "--tol" not in argv:  # the bare circuit: step's default (auto) runs a reference PNP
        argv += ["--tol", "none"]
    if cmd == "sense":
        argv += ["--curvature", draw(values(["2/m", "0", "-5", "1e4", "2m", "3 m^-1"]))]
    if cmd == "materials" and draw(st.booleans()):
        argv.insert(1, draw(st.sampled_from(MATERIAL_NAMES)))
    if cmd == "drive":
        argv += ["--waveform", draw(values(WAVEFORMS)), "--beam", "quasi-static"]
        if "--points" not in argv:
            argv += ["--points", "50"]
        if "--duration" not in argv:
            argv += ["--duration", "0.2s"]
    return argv


# ---- files ---------------------------------------------------------------------------------
FIT_COLUMNS = ["length", "width", "thickness", "voltage", "deflection", "blocking_force", "sigma_deflection",
               "sigma_blocking_force", "Voltage", "DEFLECTION", "colour"]
CELLS = {"length": ["1.5cm", "2cm", "0.02", "1e300", "1e-300"], "width": ["5mm", "0"],
         "thickness": ["200um", "150um", "1e-300", "1"], "voltage": ["0.5V", "1V", "-1V", "0", "1e-200"],
         "deflection": ["1mm", "2.1mm", "800m", "-1mm", "1e-300", "5e-324"],
         "blocking_force": ["1mN", "0.3mN", "1e300", "-1"], "sigma_deflection": ["20um", "0", "1e-300"],
         "sigma_blocking_force": ["10uN", "1e300"]}


@st.composite
def fit_csv(draw):
    cols = draw(st.lists(st.sampled_from(FIT_COLUMNS), min_size=1, max_size=5, unique=True))
    n = draw(st.integers(1, 6))
    rows = []
    for _ in range(n):
        rows.append([draw(st.sampled_from(CELLS.get(c.lower(), ["1"]) + ["", "x"])) for c in cols])
    bom = draw(st.booleans())
    text = ("\ufeff" if bom else "") + ",".join(cols) + "\n" + "\n".join(",".join(r) for r in rows) + "\n"
    return text


TOML_VALUES = ['"1V"', '"1e-300V"', "1e300", '"200um"', '"-1cm"', "0", '"abc"', "5e-324", '"2 cm"', "1e-7"]


@st.composite
def scene_toml(draw, uq=False):
    lines = ['name = "fuzz"']
    if draw(st.booleans()):
        lines.append(f'model = "{draw(st.sampled_from(MODELS))}"')
    if draw(st.booleans()) or uq:
        lines.append(f"voltage = {draw(st.sampled_from(TOML_VALUES))}")
    tol = draw(st.sampled_from(["1e-2", "5", "0", "-1", "1e-300", None]))
    if tol is not None:
        lines.append(f"tolerance = {tol}")
    lines.append('outputs = ["I", "tip_deflection", "rotation"]')
    lines.append("[strip]")
    for k in draw(st.lists(st.sampled_from(["length", "width", "thickness"]), unique=True)):
        lines.append(f"{k} = {draw(st.sampled_from(TOML_VALUES))}")
    if uq:
        lines.append("[uncertain]")
        for k, spec in draw(st.lists(st.sampled_from([
                ("thickness", '{dist = "normal", mean = "200um", sd = "8um"}'),
                ("thickness", '{dist = "normal", mean = "1e-300", sd = "1e300"}'),
                ("length", '{dist = "uniform", low = "1.95cm", high = "2.05cm"}'),
                ("modulus", '{dist = "lognormal", median = "130MPa", sigma = 1e300}'),
                ("c_moy", '{dist = "normal", mean = 3082, sd = 60}'),
                ("voltage", '{dist = "cauchy", loc = 1}'),
                ("voltage", '{dist = "triangular", low = "0.95V", mode = "1V", high = "1.05V"}')]),
                min_size=0, max_size=3, unique_by=lambda kv: kv[0])):
            lines.append(f"{k} = {spec}")
    elif draw(st.booleans()):
        n = draw(st.sampled_from(["3", "1e9", "0", "1e400"]))
        lines += ["[sweep]", f'voltage = {{start = "0.5V", stop = "2V", n = {n}}}']
    text = "\n".join(lines) + "\n"
    return ("\ufeff" if draw(st.booleans()) else "") + text


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_bytes(text.encode("utf-8"))
    return str(p)


# ---- the properties ----------------------------------------------------------------------
def test_every_command_is_covered():
    """The fuzz covers every command ``ipmc-asym --help`` lists."""
    listed = set(COMMANDS) | set(plugin_commands())
    covered = set(CHEAP) | set(WRITERS) | {"fit", "uq", "scene", "design", "warmup"}
    assert listed <= covered, listed - covered
    assert len(listed) >= 14


@pytest.mark.parametrize("argv", [["warmup", "--nope"], ["warmup", "--json", "x"], ["warmup", "--jobs", "0"],
                                  ["warmup", "--jobs", "99"], ["warmup", "--jobs", "1.5"]])
def test_warmup_refuses_in_one_line(argv):
    """warmup compiles every kernel (minutes on a cold cache): only its refusals are fuzzed here."""
    rc, out, err, _ = run_cli(argv)
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1, (rc, err)


@FAST
@given(argv=cheap_argv())
def test_fuzz_cheap_commands(argv):
    check_outcome(argv, *run_cli(argv))


@FAST
@given(text=fit_csv(), extra=options({"--free": ["modulus", "c_moy", "modulus,c_moy", "eps0", "x",
                                                  "modulus=200MPa:500MPa", "modulus=5:1"],
                                      "--fidelity": ["leading", "corrected"], "--seed": ["0", "-5", "1e30", "x"],
                                      "--multistart": ["0", "1", "1e12", "-1"], "--max-rows": ["1", "3", "0"],
                                      "--json": None, "--length": LENGTHS}, max_size=3))
@example(text="blocking_force,sigma_blocking_force\n1mN,1e300\n", extra=[])  # n = p: chi2/(n - p) is 0/0
def test_fuzz_fit_files(tmp_path_factory, text, extra):
    d = tmp_path_factory.mktemp("fit")
    argv = ["fit", _write(d, "data.csv", text), "--no-progress", "--fidelity", "corrected"] + extra
    if "--free" not in extra:
        argv += ["--free", "modulus"]
    check_outcome(argv, *run_cli(argv))


@FAST
@given(text=scene_toml(uq=True), extra=options({"--samples": ["100", "1", "1e12", "x"], "--seed": ["0", "-5"],
                                                  "--json": None}, max_size=2))
def test_fuzz_uq_files(tmp_path_factory, text, extra):
    d = tmp_path_factory.mktemp("uq")
    argv = ["uq", _write(d, "s.toml", text), "--fidelity", "leading"] + extra
    if "--samples" not in extra:
        argv += ["--samples", "100"]
    check_outcome(argv, *run_cli(argv))


@FAST
@given(text=scene_toml(), json_=st.booleans())
def test_fuzz_scene_files(tmp_path_factory, text, json_):
    d = tmp_path_factory.mktemp("scene")
    argv = ["scene", _write(d, "s.toml", text)] + (["--json"] if json_ else [])
    check_outcome(argv, *run_cli(argv))


DESIGN_VALUES = ['"1cm"', '"4cm"', '"100um"', '"400um"', '"1e-300"', '"1e300"', '"-1cm"', '"abc"', "0", '"2mm"', '"1mN"']


@st.composite
def design_toml(draw):
    v = lambda: draw(st.sampled_from(DESIGN_VALUES))  # noqa: E731
    lines = [f'model = "{draw(st.sampled_from(MODELS))}"', "[strip]", 'width = "5mm"', 'voltage = "1V"', "[vary]",
             f"length = [{v()}, {v()}]", f"thickness = [{v()}, {v()}]", "[objective]",
             f'{draw(st.sampled_from(["maximize", "minimize", "optimise"]))} = '
             f'"{draw(st.sampled_from(["blocking_force", "tip_deflection", "nope"]))}"']
    if draw(st.booleans()):
        lines += ["[constraints]", f"tip_deflection = {{min = {v()}}}"]
    return ("\ufeff" if draw(st.booleans()) else "") + "\n".join(lines) + "\n"


@FAST
@given(text=design_toml(), json_=st.booleans())
def test_fuzz_design_files(tmp_path_factory, text, json_):
    d = tmp_path_factory.mktemp("design")
    argv = ["design", _write(d, "d.toml", text)] + (["--json"] if json_ else [])
    check_outcome(argv, *run_cli(argv))


#: writers and long commands: their refusals and --help in process (a real run of each is tested
#: in its own module)
REFUSALS = [
    ["profiles", "--voltage", "1e-300V"], ["profiles", "--out", "/nonexistent/a/b"], ["profiles", "--thickness", "abc"],
    ["figures", "--dpi", "1e6"], ["figures", "--dpi", "5"], ["figures", "--out", "/proc/x/y"],
    ["validate", "--out", "/proc/r.md"], ["validate", "--out", "r.html"], ["derive", "--nope"],
    ["bench", "--points", "0"], ["bench", "--figure", "x.txt"], ["bench", "--layout", "spiral"],
    ["uq", "/nonexistent.toml"], ["scene", "/nonexistent.toml"], ["fit", "/nonexistent.csv", "--free", "modulus"],
    # unbounded reads: a device is refused before a byte is read (base.inputs)
    ["scene", "/dev/zero"], ["uq", "/dev/zero"], ["design", "/dev/zero"], ["fit", "/dev/zero", "--free", "modulus"],
    ["scene", os.path.join(ROOT, "examples", "uq_nominal.toml"), "--max-input-size", "10B"],
    ["scene", os.path.join(ROOT, "examples", "uq_nominal.toml"), "--max-input-size", "0"],
    # every output option: format from the extension, refused before the work; '' is no path
    ["drive", "--waveform", "step:1V", "--duration", "1s", "--out", "d.xlsx"],
    ["drive", "--waveform", "step:1V", "--duration", "1s", "--out", "d"],
    ["design", os.path.join(ROOT, "examples", "design_blocking_force.toml"), "--plot", "x.xlsx"],
    ["step", "--out", "s.nc"], ["freq", "--export", "e.csv"],
    ["sweep", "--vary", "voltage=1V:2V:3", "--out", ""], ["validate", "--out", ""], ["figures", "--out", ""],
    ["uq", os.path.join(ROOT, "examples", "uq_nominal.toml"), "--out", ""], ["profiles", "--out", ""],
    ["sweep", "--vary", "voltage=1V:2V:2000000", "--out", "s.nc"],
    # messages
    ["step", "--duration", "1e30"], ["drive", "--waveform", "step:1V", "--duration", "1e30"],
    ["freq", "--export-tol", "0"], ["drive", "--waveform", "sine:1V@10Hz,nan", "--duration", "1s"],
]


@pytest.mark.parametrize("argv", REFUSALS + [[c, "--help"] for c in
                                             ("profiles", "figures", "validate", "derive", "bench")])
def test_writers_and_long_commands_refuse_in_one_line(argv, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rc, out, err, peak = run_cli(argv)
    check_outcome(argv, rc, out, err, peak)
    assert rc == (0 if "--help" in argv else 2)
    assert os.listdir(tmp_path) == []


#: the writers and long commands with random options and a target that cannot be written: a
#: one-line refusal (or a --help), never the work itself
BAD_DIRS = ["/nonexistent/a/b", "/proc/x/y", "a\0b"]
BAD_FILES = BAD_DIRS + ["out.xlsx", "/nonexistent/x.png", "/proc/r.md"]
WRITERS = {
    "profiles": ({**STRIP, "--voltage": VOLTS, "--model": MODELS, "--json": None}, "--out"),
    "figures": ({"--dpi": COUNTS, "--quick": None, "--bench": ["/nonexistent.json"]}, "--out"),
    "validate": ({"--json": None}, "--out"),
    "bench": ({"--points": COUNTS, "--bvp-points": COUNTS, "--layout": ["grid", "random", "spiral"],
               "--no-compile": None, "--quick": None}, "--figure"),
    "derive": ({"--print": ["--check"], "--nope": None}, None),
}


@st.composite
def writer_argv(draw):
    cmd = draw(st.sampled_from(sorted(WRITERS)))
    table, out = WRITERS[cmd]
    argv = [cmd] + draw(options(table, max_size=3))
    if out is not None:
        argv += [out, draw(st.sampled_from(BAD_DIRS if cmd in ("profiles", "figures") else BAD_FILES))]
    elif "--nope" not in argv:
        argv += ["--nope"]
    return argv


@FAST
@given(argv=writer_argv())
def test_fuzz_writers_refuse_before_the_work(argv, tmp_path_factory):
    d = tmp_path_factory.mktemp("w")
    cwd = os.getcwd()
    os.chdir(d)
    try:
        rc, out, err, peak = run_cli(argv)
    finally:
        os.chdir(cwd)
    check_outcome(argv, rc, out, err, peak)
    assert rc == 2 and os.listdir(d) == [], (argv, err)


#: a few real runs in a child process: exit status, output and the child's peak memory
SUBPROCESS = [
    ["step", "--points", "1e9"],
    ["freq", "--from", "1Hz", "--to", "1kHz", "--points", "1e7", "--json"],
    ["uq", os.path.join(ROOT, "examples", "uq_nominal.toml"), "--samples", "1e12"],
    ["sweep", "--vary", "voltage=1e-300:1e-200:3:log", "--fidelity", "leading", "--no-progress"],
    ["derive", "--print"],
]


@pytest.mark.parametrize("argv", SUBPROCESS)
def test_subprocess_runs_bounded(argv):
    rc, out, err, peak = _run_child([sys.executable, "-m", "ipmc_asym", *argv], {**os.environ, "PYTHONPATH": ROOT})
    check_outcome(argv, rc, out, err, peak=peak)


#: started with ``-I -S`` (a few MB): runs the command, then writes its only child's peak
#: (``RUSAGE_CHILDREN``) to the file named first, and exits with the child's status
_LAUNCHER = """
import os, resource, signal, subprocess, sys
rc = subprocess.call(sys.argv[3:], timeout=float(sys.argv[2]))
with open(sys.argv[1], "w") as fh:
    fh.write(str(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss))
if rc < 0:  # killed: die by the same signal, as the child did
    try:
        signal.signal(-rc, signal.SIG_DFL)
    except (OSError, ValueError):  # SIGKILL, SIGSTOP: no handler to reset
        pass
    os.kill(os.getpid(), -rc)
sys.exit(rc)
"""


def _run_child(cmd, env, timeout=600):
    """(status, stdout, stderr, peak bytes) of one child, started by :data:`_LAUNCHER`."""
    import tempfile

    with tempfile.TemporaryDirectory() as d, open(os.path.join(d, "o"), "w+") as fo, \
            open(os.path.join(d, "e"), "w+") as fe:
        peak_file = os.path.join(d, "peak")
        launcher = [sys.executable, "-I", "-S", "-c", _LAUNCHER, peak_file, str(timeout)]
        rc = subprocess.call(launcher + list(cmd), stdout=fo, stderr=fe, env=env)
        fo.seek(0)
        fe.seek(0)
        with open(peak_file) as fh:
            kb = int(fh.read())
        return rc, fo.read(), fe.read(), kb if sys.platform == "darwin" else kb * 1024


@pytest.mark.slow
@SLOW
@given(argv=cheap_argv())
def test_fuzz_cheap_commands_long(argv):
    check_outcome(argv, *run_cli(argv))


@pytest.mark.slow
@SLOW
@given(text=fit_csv(), free=st.sampled_from(["modulus", "c_moy", "modulus,c_moy"]))
def test_fuzz_fit_files_long(tmp_path_factory, text, free):
    d = tmp_path_factory.mktemp("fit")
    argv = ["fit", _write(d, "data.csv", text), "--free", free, "--no-progress"]
    check_outcome(argv, *run_cli(argv))


@pytest.mark.slow
@SLOW
@given(text=scene_toml(uq=True))
def test_fuzz_uq_files_long(tmp_path_factory, text):
    d = tmp_path_factory.mktemp("uq")
    argv = ["uq", _write(d, "s.toml", text), "--samples", "200"]
    check_outcome(argv, *run_cli(argv))
