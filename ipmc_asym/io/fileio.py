"""Output files: the one set of rules every command follows.

* **Format from the extension.**  :func:`check_output_path` with ``formats`` accepts only
  the listed extensions (case-insensitive) and refuses any other in one line listing them:
  a ``.csv`` name never receives NetCDF bytes, nor ``.xlsx`` CSV text.
* **Checked before the work.**  Every command calls :func:`check_output_path` on each
  output target before computing.  Writability is probed by creating (and removing) a file
  in the target directory, because ``os.access`` says yes to root on ``/proc`` or a
  read-only mount.  Messages name the path the user gave.
* **Directories.**  An output directory may be missing only at its last level: it is
  created (:func:`make_output_dir`); a missing parent is refused -- the same rule for every
  command (no chain of directories created by a typo).
* **Atomic.**  Files are written through :func:`atomic_write` / :func:`atomic_path` (a
  temporary file in the same directory, renamed over the target on success, removed on any
  error or Ctrl-C), so no partial file is ever left; an ``OSError`` names the target, not
  the temporary file.
* **Interruptible.**  Under the command line's signal handling (``base.interrupt``) every
  write through :func:`atomic_write` and every rename checks the interruption flag, so a
  Ctrl-C, SIGTERM or SIGHUP whose exception was swallowed inside compiled code still stops
  a streaming writer at its next chunk and no file is committed after it.
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
import tempfile

from ipmc_asym.base import interrupt

__all__ = ["check_output_path", "atomic_write", "atomic_path", "make_output_dir", "output_format",
           "FIGURE_FORMATS"]

#: extensions of figure files (matplotlib writes each from the name)
FIGURE_FORMATS = (".png", ".pdf", ".svg")


def _umask_mode() -> int:
    """The mode a plain ``open(path, "w")`` would give (mkstemp makes files 0600)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def output_format(path, formats, what: str = "--out") -> str:
    """The extension of ``path`` (lower case, with the dot) if it is one of ``formats``.

    Raises
    ------
    ValueError
        One line naming ``what``, the path and the allowed extensions.
    """
    p = os.fspath(path)
    ext = os.path.splitext(p)[1].lower()
    allowed = tuple(f.lower() for f in formats)
    if ext not in allowed:
        got = f"extension {ext!r}" if ext else "no extension"
        raise ValueError(f"{what} {p!r}: {got}; the format follows the extension, allowed: {', '.join(allowed)}")
    return ext


def _probe_writable(d: str, p: str, what: str) -> None:
    """Create and remove a file in directory ``d`` (the only reliable test, also for root)."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".ipmc-asym-probe.", dir=d)
    except OSError as exc:
        raise ValueError(f"{what} {p!r}: cannot write in {d!r} ({exc.strerror or exc.__class__.__name__})") from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(tmp)


def check_output_path(path, kind: str = "file", what: str = "--out", formats=None) -> str:
    """Check that ``path`` can be written; one-line ``ValueError`` otherwise.

    Parameters
    ----------
    path : str or os.PathLike
    kind : {"file", "dir"}
        A file whose directory must exist and be writable (and that is not a directory), or
        a directory that exists writable, or whose parent exists writable (then only the last
        level is created, by :func:`make_output_dir`).
    what : str
        The option or parameter named in the message.
    formats : sequence of str, optional
        Allowed extensions of a file (``(".csv", ".json")``); any other is refused.

    Returns
    -------
    str
        The path as a string.
    """
    p = os.fspath(path)
    if not p:
        raise ValueError(f"{what} must be a path; got an empty string")
    if "\0" in p:
        raise ValueError(f"{what} {p!r}: a path cannot contain a NUL character")
    if kind == "file":
        if formats is not None:
            output_format(p, formats, what)
        if os.path.isdir(p):
            raise ValueError(f"{what} {p!r} is a directory; give a file name")
        d = os.path.dirname(os.path.abspath(p))
        if not os.path.isdir(d):
            raise ValueError(f"{what} {p!r}: directory {os.path.dirname(p) or d!r} does not exist")
        if os.path.exists(p) and not os.access(p, os.W_OK):
            raise ValueError(f"{what} {p!r}: not writable")
        _probe_writable(d, p, what)
    elif kind == "dir":
        if os.path.exists(p) and not os.path.isdir(p):
            raise ValueError(f"{what} {p!r} exists and is not a directory")
        if os.path.isdir(p):
            _probe_writable(p, p, what)
        else:
            parent = os.path.dirname(os.path.abspath(p))
            if not os.path.isdir(parent):
                raise ValueError(f"{what} {p!r}: parent directory {parent!r} does not exist (only the last level "
                                 f"of an output directory is created)")
            _probe_writable(parent, p, what)
    else:
        raise ValueError(f"kind must be 'file' or 'dir'; got {kind!r}")
    return p


def make_output_dir(path, what: str = "--out") -> str:
    """Create output directory ``path`` if missing -- its last level only (the parent must exist)."""
    p = check_output_path(path, "dir", what)
    if not os.path.isdir(p):
        try:
            os.mkdir(p)
        except FileExistsError:
            pass
        except OSError as exc:
            raise ValueError(f"{what} {p!r}: cannot create ({exc.strerror or exc.__class__.__name__})") from None
    return p


def _named(exc: OSError, p: str) -> OSError:
    """The same error, naming the user's path instead of the temporary file."""
    return OSError(exc.errno if exc.errno is not None else errno.EIO, exc.strerror or str(exc), p)


@contextlib.contextmanager
def atomic_write(path, mode: str = "w", **open_kw):
    """Open a temporary file beside ``path``; rename it to ``path`` only on success.

    Yields
    ------
    file object
        Opened with ``mode`` (``"w"``, ``"wb"``, ...).  On an exception (including
        ``KeyboardInterrupt``) the temporary file is removed and ``path`` is untouched; an
        ``OSError`` is raised naming ``path``.
    """
    p = os.fspath(path)
    if "b" not in mode:
        open_kw.setdefault("encoding", "utf-8")
        open_kw.setdefault("newline", "")
    try:
        kind = os.stat(p).st_mode
    except OSError:
        kind = None
    if kind is not None and not stat.S_ISREG(kind) and not stat.S_ISDIR(kind):
        # a device or a FIFO (/dev/null, /dev/stdout): written in place; renaming a file over it
        # would replace the device with a regular file (as root, /dev/null itself)
        with open(p, mode, **open_kw) as fh:
            yield _Checked(fh)
        return
    d = os.path.dirname(os.path.abspath(p))
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(p)}.", suffix=".part", dir=d)
    except OSError as exc:
        raise _named(exc, p) from None
    try:
        with os.fdopen(fd, mode, **open_kw) as fh:
            yield _Checked(fh)
        interrupt.check()  # an interruption swallowed during the work: nothing committed
        os.chmod(tmp, _umask_mode())
        os.replace(tmp, p)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError) and not isinstance(exc, BrokenPipeError) and exc.filename in (tmp, None):
            raise _named(exc, p) from None
        raise


class _Checked:
    """A file object whose ``write`` first checks the interruption flag (one check per chunk of a
    streaming writer); every other attribute is the file's."""

    __slots__ = ("_fh",)

    def __init__(self, fh):
        self._fh = fh

    def write(self, data):
        interrupt.check()
        return self._fh.write(data)

    def writelines(self, lines):
        interrupt.check()
        return self._fh.writelines(lines)

    @property
    def buffer(self):
        """The binary layer of a text file, checked the same way."""
        return _Checked(self._fh.buffer)

    def __getattr__(self, name):
        return getattr(self._fh, name)

    def __iter__(self):
        return iter(self._fh)


def atomic_path(path):
    """A context manager yielding a temporary path beside ``path`` (for writers that take a
    file name, e.g. matplotlib's ``savefig`` or xarray's ``to_netcdf``); renamed on success."""
    return _AtomicPath(path)


class _AtomicPath:
    def __init__(self, path):
        self.path = os.fspath(path)

    def __enter__(self):
        d = os.path.dirname(os.path.abspath(self.path))
        base, ext = os.path.splitext(os.path.basename(self.path))
        try:
            fd, self.tmp = tempfile.mkstemp(prefix=f".{base}.", suffix=f".part{ext}", dir=d)
        except OSError as exc:
            raise _named(exc, self.path) from None
        os.close(fd)
        return self.tmp

    def __exit__(self, et, ev, tb):
        if et is None:
            try:
                interrupt.check()  # an interruption swallowed during the work: nothing committed
                os.chmod(self.tmp, _umask_mode())
                os.replace(self.tmp, self.path)
            except BaseException as exc:
                with contextlib.suppress(OSError):
                    os.unlink(self.tmp)
                if isinstance(exc, OSError):
                    raise _named(exc, self.path) from None
                raise
            return False
        with contextlib.suppress(OSError):
            os.unlink(self.tmp)
        if isinstance(ev, OSError) and not isinstance(ev, BrokenPipeError) and ev.filename in (self.tmp, None):
            raise _named(ev, self.path) from None
        return False
