"""Interruption: Ctrl-C, SIGTERM and SIGHUP end a command the same way.

The command line installs :func:`handling_signals` around a command (the previous handlers
are restored on exit, so using the library imports no handler).  Each of the three signals

* records itself in a flag (:func:`pending`), and
* raises :class:`Interrupted` (a ``KeyboardInterrupt``: every ``finally`` / ``except
  BaseException`` cleanup, e.g. ``io.fileio.atomic_write`` removing its ``.part`` file, runs as
  for Ctrl-C).

An exception raised from a signal handler would be swallowed when the signal arrives inside a
callback from compiled code (a Numba/llvmlite cache callback drops it, and the JIT is left
half-updated), so there the handler only sets the flag; the flag is never lost:
streaming writers call :func:`check` between chunks (``io.fileio.atomic_write`` does on every
write and before renaming) and the command line when a command returns, so an interruption is never
lost and no output file is committed after it.  The exit status is ``128 + signal number`` (130, 143, 129), the shell's convention.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading

__all__ = ["Interrupted", "handling_signals", "check", "pending", "SIGNALS", "exit_status"]

#: the signals ending a command cleanly (SIGHUP is missing on Windows)
SIGNALS = tuple(s for s in (getattr(signal, n, None) for n in ("SIGINT", "SIGTERM", "SIGHUP")) if s is not None)

_pending: list = []  # signal numbers received while handling_signals is active


class Interrupted(KeyboardInterrupt):
    """Raised on SIGINT, SIGTERM or SIGHUP under :func:`handling_signals`.

    Attributes
    ----------
    signum : int
        The signal number (2, 15, 1).
    """

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = int(signum)

    @property
    def name(self) -> str:
        """``SIGINT`` (shown as Ctrl-C), ``SIGTERM``, ``SIGHUP``."""
        try:
            return signal.Signals(self.signum).name
        except ValueError:
            return f"signal {self.signum}"


def exit_status(exc: BaseException) -> int:
    """``128 + signal number`` of an interruption (130 for a plain ``KeyboardInterrupt``)."""
    return 128 + (exc.signum if isinstance(exc, Interrupted) else int(signal.SIGINT))


def _in_compiled_callback(frame) -> bool:
    """Whether ``frame`` runs inside a callback from llvmlite's compiled code (Numba's object cache
    loading or storing a kernel): an exception raised there is dropped by ``ctypes`` and leaves the
    JIT's state half-updated (a later call can crash with SIGSEGV: Ctrl-C while ``drive`` loads its
    kernels)."""
    marker = os.sep + "llvmlite" + os.sep
    while frame is not None:
        if marker in frame.f_code.co_filename:
            return True
        frame = frame.f_back
    return False


def _handler(signum, frame):
    _pending.append(int(signum))
    # inside the JIT's callbacks only the flag is set: the next check() (between chunks, before a file
    # is committed, and by the command line when the command returns) raises it
    if not _in_compiled_callback(frame):
        raise Interrupted(signum)


def pending() -> int | None:
    """The first signal received under :func:`handling_signals` and not yet cleared, or None."""
    return _pending[0] if _pending else None


def check() -> None:
    """Raise :class:`Interrupted` if a signal was received (even if its exception was swallowed)."""
    if _pending:
        raise Interrupted(_pending[0])


@contextlib.contextmanager
def handling_signals():
    """Within the block, SIGINT/SIGTERM/SIGHUP raise :class:`Interrupted` and set the flag.

    Only in the main thread (``signal.signal`` is refused elsewhere: then nothing is
    installed); a signal the caller ignores (``nohup``) stays ignored.  The previous handlers are restored and the flag cleared on exit.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {}
    try:
        for s in SIGNALS:
            if signal.getsignal(s) is signal.SIG_IGN:
                continue  # ignored on purpose (nohup, a background job): stays ignored
            previous[s] = signal.signal(s, _handler)
        yield
    finally:
        for s, h in previous.items():
            with contextlib.suppress(ValueError, OSError, TypeError):
                signal.signal(s, h if h is not None else signal.SIG_DFL)
        _pending.clear()
