"""Ctrl-C, SIGTERM and SIGHUP end a command alike: no ``.NAME.*.part`` file, no sidecar without its
CSV, no traceback, exit status 128 + the signal number (the shell's convention: 130, 143, 129).

The real runs are child processes signalled while they stream a file; the swallowed-interrupt
case (a KeyboardInterrupt dropped inside a Numba/llvmlite callback) is reproduced in process by
swallowing the handler's exception: the flag must still stop the writer and commit nothing.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest
from references import REPO

from ipmc_asym.base import interrupt
from ipmc_asym.io.fileio import atomic_path, atomic_write

ENV = {**os.environ, "PYTHONPATH": str(REPO)}


#: the child starts as a terminal's foreground job does: the three signals at their defaults and
#: unblocked.  A child inherits an ignored disposition and the blocked mask of the process that
#: starts it, and a test worker's may differ (a SIGINT ignored or blocked there reaches no handler,
#: and the CLI keeps an ignored signal ignored on purpose: ``nohup``)
CHILD = ("import runpy, signal, sys\n"
         "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
         "for s in (signal.SIGTERM, signal.SIGHUP):\n"
         "    signal.signal(s, signal.SIG_DFL)\n"
         "signal.pthread_sigmask(signal.SIG_UNBLOCK, (signal.SIGINT, signal.SIGTERM, signal.SIGHUP))\n"
         "sys.argv[0] = 'ipmc-asym'\n"
         "runpy.run_module('ipmc_asym', run_name='__main__', alter_sys=True)\n")


def _signal_state(pid):
    """The child's blocked, ignored and caught signal masks (``/proc``), for a failure's message."""
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as fh:
            return " ".join(line.strip() for line in fh if line.startswith(("SigBlk", "SigIgn", "SigCgt")))
    except OSError:
        return "(no /proc)"


def _signalled_run(argv, tmp_path, sig, wait_for):
    """Start ``ipmc-asym argv`` in ``tmp_path``, send ``sig`` once ``wait_for()`` holds;
    (rc, stderr + the child's signal masks when it was signalled)."""
    p = subprocess.Popen([sys.executable, "-c", CHILD, *argv], cwd=tmp_path, env=ENV,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        t0 = time.monotonic()
        while not wait_for() and p.poll() is None and time.monotonic() - t0 < 300:
            time.sleep(0.05)
        assert p.poll() is None, f"finished before the signal: {p.stderr.read()[-2000:]}"
        time.sleep(0.3)  # inside the streaming loop
        state = _signal_state(p.pid)
        p.send_signal(sig)
        _, err = p.communicate(timeout=120)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    return p.returncode, err + f"\n[child signal masks when signalled: {state}]"


def _parts(d):
    return [f for f in os.listdir(d) if f.endswith(".part") or ".part." in f]


@pytest.mark.parametrize("sig, status", [(signal.SIGTERM, 143), (signal.SIGHUP, 129), (signal.SIGINT, 130)])
def test_drive_streaming_ends_cleanly_on_each_signal(tmp_path, sig, status):
    # long enough to be streaming when signalled (~10^7 rows, quasi-static: a few minutes)
    argv = ["drive", "--waveform", "sine:1V@10Hz", "--duration", "100s", "--points", "1e7", "--beam",
            "quasi-static", "--out", "d.csv"]
    rc, err = _signalled_run(argv, tmp_path, sig, lambda: bool(_parts(tmp_path)))
    assert rc == status, err[-2000:]
    assert "Traceback" not in err, err[-2000:]
    assert "interrupted" in err and "no partial output file left" in err
    # nothing left: no temporary file, no CSV, and no sidecar F.csv.json without its CSV
    assert os.listdir(tmp_path) == [], os.listdir(tmp_path)


def test_sweep_streaming_ends_cleanly_on_sigterm(tmp_path):
    argv = ["sweep", "--vary", "thickness=10um:1mm:3000:log", "--vary", "voltage=0.1V:3V:3000", "--max-rows", "1e7",
            "--fidelity", "leading", "--no-progress", "--out", "s.csv"]
    rc, err = _signalled_run(argv, tmp_path, signal.SIGTERM, lambda: bool(_parts(tmp_path)))
    assert rc == 143 and "Traceback" not in err, err[-2000:]
    assert os.listdir(tmp_path) == []


def test_startup_interrupt_has_no_traceback(tmp_path):
    """Ctrl-C while the command's modules are imported (NumPy, Numba): one line, status 130."""
    code = ("import sys, importlib.abc\n"
            "class Stop(importlib.abc.MetaPathFinder):\n"
            "    def find_spec(self, name, path=None, target=None):\n"
            "        if name == 'ipmc_asym.cli.common':\n"
            "            raise KeyboardInterrupt\n"
            "sys.meta_path.insert(0, Stop())\n"
            "from ipmc_asym.cli import main\n"
            "sys.exit(main(['estimate']))\n")
    r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=ENV, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 130, r.stderr
    assert "Traceback" not in r.stderr and r.stderr.count("\n") == 1, r.stderr


def test_swallowed_interrupt_still_stops_the_writer(tmp_path):
    """The handler's exception swallowed (as inside a compiled callback): the flag stops the next
    write and the commit; no file, no temporary file."""
    target = tmp_path / "out.csv"
    with pytest.raises(interrupt.Interrupted) as info, interrupt.handling_signals(), atomic_write(target) as fh:
        fh.write("t,sigma\n")
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.1)
        except KeyboardInterrupt:
            pass  # dropped, as Numba's cache callback does
        fh.write("0,1\n")
    assert info.value.signum == signal.SIGTERM and interrupt.exit_status(info.value) == 143
    assert os.listdir(tmp_path) == []


def test_swallowed_interrupt_commits_no_atomic_path(tmp_path):
    target = tmp_path / "f.png"
    with pytest.raises(interrupt.Interrupted), interrupt.handling_signals(), atomic_path(target) as tmp:
        with open(tmp, "w") as fh:
            fh.write("x")
        try:
            os.kill(os.getpid(), signal.SIGHUP)
            time.sleep(0.1)
        except KeyboardInterrupt:
            pass
    assert os.listdir(tmp_path) == []


def test_handlers_restored_and_library_installs_none():
    before = {s: signal.getsignal(s) for s in interrupt.SIGNALS}
    import ipmc_asym as ia

    ia.evaluate(ia.Strip())  # the library alone: no handler installed
    assert {s: signal.getsignal(s) for s in interrupt.SIGNALS} == before
    with interrupt.handling_signals():
        assert signal.getsignal(signal.SIGTERM) is not before[signal.SIGTERM]
    assert {s: signal.getsignal(s) for s in interrupt.SIGNALS} == before
    assert interrupt.pending() is None
