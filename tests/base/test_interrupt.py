"""Signals under ``handling_signals``: raised where Python can unwind, only flagged inside the JIT's
callbacks (llvmlite's ctypes callbacks drop an exception and are left half-updated), and never lost."""

import os
import signal

import pytest

from ipmc_asym.base import interrupt


def _fake_llvmlite_callback():
    """A function whose code lives under an ``llvmlite`` directory, as Numba's object-cache callbacks do."""
    path = os.path.join(os.sep, "site-packages", "llvmlite", "binding", "executionengine.py")
    ns = {}
    exec(compile("def callback(f):\n    return f()\n", path, "exec"), ns)
    return ns["callback"]


def test_a_signal_inside_a_jit_callback_is_flagged_and_raised_at_the_next_check():
    callback = _fake_llvmlite_callback()
    with interrupt.handling_signals():
        # inside the callback: no exception (ctypes would drop it), the flag is set
        callback(lambda: signal.raise_signal(signal.SIGTERM))
        assert interrupt.pending() == signal.SIGTERM
        with pytest.raises(interrupt.Interrupted) as ex:
            interrupt.check()
        assert ex.value.signum == signal.SIGTERM and interrupt.exit_status(ex.value) == 143
    assert interrupt.pending() is None  # cleared with the handlers


def test_a_signal_elsewhere_raises_at_once():
    with interrupt.handling_signals():
        with pytest.raises(interrupt.Interrupted):
            signal.raise_signal(signal.SIGHUP)
            pytest.fail("the handler did not raise")


def test_the_command_line_ends_with_the_signal_s_status_when_it_was_only_flagged(monkeypatch, capsys):
    """A signal flagged inside a callback during a command that then completes: main still exits
    128 + signum (the command line checks the flag when the command returns)."""
    from ipmc_asym import cli

    callback = _fake_llvmlite_callback()
    real = cli._run

    def run_and_signal(*a, **kw):
        rc = real(*a, **kw)
        callback(lambda: signal.raise_signal(signal.SIGINT))
        return rc

    monkeypatch.setattr(cli, "_run", run_and_signal)
    # Python's own SIGINT handler, whatever this process inherited: a shell starts a background job
    # with SIGINT ignored, and an ignored signal stays ignored under handling_signals (nohup)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        rc = cli.main(["laws", "--model", "constant"])
    finally:
        signal.signal(signal.SIGINT, previous)
    assert rc == 130
    assert "interrupted (Ctrl-C)" in capsys.readouterr().err
