"""The one progress helper for everything long (BVP loops, sweeps, fits, figures, bench).

On stderr, so that JSON/CSV on stdout stay clean.  In a terminal a tqdm bar; elsewhere (a log
file, a pipe, CI) one plain line every :data:`LINE_INTERVAL_S` seconds of work, so that a long
run is never silent and a log holds no carriage returns.  Work shorter than that interval
prints nothing either way.  ``enabled=False`` silences it (``--no-progress``).
"""

from __future__ import annotations

import sys
import time

__all__ = ["progress", "LINE_INTERVAL_S"]

#: seconds between two progress lines when stderr is not a terminal
LINE_INTERVAL_S = 5.0


class _Lines:
    """A tqdm-like counter that writes ``desc: n/total unit (p %), t s`` every ``interval`` seconds."""

    def __init__(self, total, desc, unit, interval):
        self.total, self.desc, self.unit, self.interval = total, desc, unit, interval
        self.n = 0
        self.t0 = self.last = time.monotonic()

    def update(self, k=1):
        self.n += k
        now = time.monotonic()
        if now - self.last >= self.interval:
            self.last = now
            done = f"{self.n}/{self.total} {self.unit}" if self.total else f"{self.n} {self.unit}"
            pct = f" ({100.0 * self.n / self.total:.0f} %)" if self.total else ""
            sys.stderr.write(f"ipmc-asym: {self.desc or 'working'}: {done}{pct}, {now - self.t0:.0f} s\n")
            sys.stderr.flush()

    def close(self):
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


class _Off(_Lines):
    def update(self, k=1):
        self.n += k


def progress(total: int | None = None, desc: str = "", enabled: bool | None = None, unit: str = "it"):
    """Progress of a long loop on stderr.

    Parameters
    ----------
    total : int, optional
        Number of steps (``bar.update(k)`` adds ``k``).
    desc : str
        Label shown before the count.
    enabled : bool, optional
        ``False``: silent.  ``None`` or ``True``: a tqdm bar when stderr is a terminal, else a
        line every :data:`LINE_INTERVAL_S` seconds.

    Returns
    -------
    object
        With ``update(k)``, ``close()`` and the context-manager protocol (a ``tqdm.tqdm`` in a
        terminal).
    """
    if enabled is False:
        return _Off(total, desc, unit, LINE_INTERVAL_S)
    if not sys.stderr.isatty():
        return _Lines(total, desc, unit, LINE_INTERVAL_S)
    from tqdm import tqdm  # deferred: ~50 ms, only a terminal gets a bar

    return tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, leave=False, dynamic_ncols=True, mininterval=0.2)
