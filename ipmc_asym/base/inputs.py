"""Input files: the one reader every input file goes through (scenes, fit data, uq scenes,
design specs, material files, waveform CSVs, saved benchmarks).

* **Regular files only.**  ``/dev/zero``, a FIFO or a directory is refused in one line: it
  would be read until memory runs out, or block.  The file is opened without blocking and
  checked on the open descriptor (no race between the check and the read).
* **Bounded.**  At most :func:`max_input_bytes` bytes (default :data:`MAX_INPUT_BYTES`,
  set for a block by :func:`input_size_cap`; the command line's ``--max-input-size``): a
  larger file is refused before it is read, and the read itself stops one byte past the cap
  (a file growing while read is refused too).
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import re
import stat

__all__ = ["MAX_INPUT_BYTES", "max_input_bytes", "input_size_cap", "read_input_bytes", "read_input_text",
           "parse_size"]

#: default cap on the size of one input file (bytes): far above any scene, spec or data file of
#: this toolkit (kilobytes; a 10^5-row calibration CSV is a few MB), far below the memory
MAX_INPUT_BYTES = 64 * 2**20

_cap = contextvars.ContextVar("max_input_bytes", default=MAX_INPUT_BYTES)

_SIZE = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([kKMGT]i?B|B)?\s*$")
_FACTORS = {None: 1, "B": 1, "kB": 10**3, "KB": 10**3, "MB": 10**6, "GB": 10**9, "TB": 10**12,
            "KiB": 2**10, "kiB": 2**10, "MiB": 2**20, "GiB": 2**30, "TiB": 2**40}


def parse_size(text, what: str = "--max-input-size", maximum: int | None = None) -> int:
    """``"64MB"``, ``"1GiB"``, ``"5e6"`` (bytes) -> an integer number of bytes >= 1 (and <= ``maximum``,
    the ceiling of a cap, where given).

    Raises
    ------
    ValueError
        One line naming ``what`` and the accepted forms (or the ceiling).
    """
    m = _SIZE.match(str(text))
    n = None
    if m and m.group(2) in _FACTORS:
        v = float(m.group(1)) * _FACTORS[m.group(2)]
        n = int(v) if v == v and 1 <= v < 2**63 else (2**63 if v >= 2**63 else None)
    if n is None:
        raise ValueError(f"{what} must be a size in bytes >= 1, e.g. 64MB, 1GiB or 5e6; got {text!r}")
    if maximum is None and n >= 2**63:
        raise ValueError(f"{what} must be a size below 2^63 bytes; got {text!r}")
    if maximum is not None and n > maximum:
        raise ValueError(f"{what} must be a size from 1 to {maximum} bytes ({_binary(maximum)}; the ceiling of this "
                         f"cap: memory stays bounded); got {text!r}")
    return n


def _binary(n: int) -> str:
    """``n`` bytes in the largest binary unit that divides it (1 GiB, 64 MiB), else in bytes."""
    for unit, f in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n % f == 0:
            return f"{n // f} {unit}"
    return f"{n} B"


def max_input_bytes() -> int:
    """The cap on one input file (bytes) in effect."""
    return _cap.get()


@contextlib.contextmanager
def input_size_cap(n: int):
    """Within the block, input files larger than ``n`` bytes are refused."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ValueError(f"max input size must be an integer number of bytes >= 1; got {n!r}")
    token = _cap.set(n)
    try:
        yield
    finally:
        _cap.reset(token)


def read_input_bytes(path, what: str = "input file") -> bytes:
    """The bytes of input file ``path`` (a regular file of at most :func:`max_input_bytes` bytes).

    Parameters
    ----------
    path : str or os.PathLike
    what : str
        Named in the messages (``"scene file"``, ``"data file"``).

    Raises
    ------
    OSError
        The file cannot be opened or read (missing, permission): the caller words it.
    ValueError
        Not a regular file, or larger than the cap: one line naming ``what`` and the path.
    """
    p = os.fspath(path)
    cap = max_input_bytes()
    # non-blocking open: a FIFO would otherwise block here before it can be refused
    fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = "a directory" if stat.S_ISDIR(st.st_mode) else "not a regular file (a device, FIFO or socket)"
            raise ValueError(f"{what} {p!r} is {kind}; give a file")
        if st.st_size > cap:
            raise ValueError(f"{what} {p!r} is {st.st_size} bytes, more than the cap {cap} "
                             f"(--max-input-size on the command line)")
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(cap + 1)
    finally:
        os.close(fd)
    if len(data) > cap:
        raise ValueError(f"{what} {p!r} is more than the cap {cap} bytes (--max-input-size on the command line)")
    return data


def read_input_text(path, what: str = "input file", encoding: str = "utf-8") -> str:
    """The text of input file ``path`` (as :func:`read_input_bytes`, decoded; ``UnicodeDecodeError``
    propagates for the caller to word)."""
    return read_input_bytes(path, what).decode(encoding)
