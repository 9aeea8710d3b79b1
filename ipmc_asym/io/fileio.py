"""Output files: paths checked before the work, files written atomically.

Every command that writes a file calls :func:`check_output_path` before computing and
writes through :func:`atomic_write` (a temporary file in the same directory, renamed over
the target on success, removed on any error or Ctrl-C), so no partial file is ever left.
"""

from __future__ import annotations

import contextlib
import os
import tempfile


def _umask_mode() -> int:
    """The mode a plain ``open(path, "w")`` would give (mkstemp makes files 0600)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask

__all__ = ["check_output_path", "atomic_write"]


def check_output_path(path, kind: str = "file", what: str = "--out") -> str:
    """Check that ``path`` can be written; one-line ``ValueError`` otherwise.

    Parameters
    ----------
    path : str or os.PathLike
    kind : {"file", "dir"}
        A file whose directory must exist and be writable (and that is not a directory),
        or a directory that exists writable or can be created (its parent writable).
    what : str
        The option or parameter named in the message.

    Returns
    -------
    str
        The path as a string.
    """
    p = os.fspath(path)
    if not p:
        raise ValueError(f"{what} must be a path; got an empty string")
    if kind == "file":
        if os.path.isdir(p):
            raise ValueError(f"{what} {p!r} is a directory; give a file name")
        d = os.path.dirname(os.path.abspath(p))
        if not os.path.isdir(d):
            raise ValueError(f"{what} {p!r}: directory {d!r} does not exist")
        if not os.access(d, os.W_OK) or (os.path.exists(p) and not os.access(p, os.W_OK)):
            raise ValueError(f"{what} {p!r}: not writable")
    elif kind == "dir":
        if os.path.exists(p) and not os.path.isdir(p):
            raise ValueError(f"{what} {p!r} exists and is not a directory")
        probe = os.path.abspath(p)
        while not os.path.exists(probe):
            parent = os.path.dirname(probe)
            if parent == probe:
                break
            probe = parent
        if not os.path.isdir(probe) or not os.access(probe, os.W_OK):
            raise ValueError(f"{what} {p!r}: not writable (nearest existing directory {probe!r})")
    else:
        raise ValueError(f"kind must be 'file' or 'dir'; got {kind!r}")
    return p


@contextlib.contextmanager
def atomic_write(path, mode: str = "w", **open_kw):
    """Open a temporary file beside ``path``; rename it to ``path`` only on success.

    Yields
    ------
    file object
        Opened with ``mode`` (``"w"``, ``"wb"``, ...).  On an exception (including
        ``KeyboardInterrupt``) the temporary file is removed and ``path`` is untouched.
    """
    p = os.fspath(path)
    d = os.path.dirname(os.path.abspath(p))
    fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(p)}.", suffix=".part", dir=d)
    try:
        if "b" not in mode:
            open_kw.setdefault("encoding", "utf-8")
            open_kw.setdefault("newline", "")
        with os.fdopen(fd, mode, **open_kw) as fh:
            yield fh
        os.chmod(tmp, _umask_mode())
        os.replace(tmp, p)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


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
        fd, self.tmp = tempfile.mkstemp(prefix=f".{base}.", suffix=f".part{ext}", dir=d)
        os.close(fd)
        return self.tmp

    def __exit__(self, et, ev, tb):
        if et is None:
            os.chmod(self.tmp, _umask_mode())
            os.replace(self.tmp, self.path)
        else:
            with contextlib.suppress(OSError):
                os.unlink(self.tmp)
        return False


__all__.append("atomic_path")
