"""The one progress helper for everything long (BVP loops, sweeps, figures, bench).

A thin wrapper over tqdm writing to stderr, so that JSON/CSV on stdout stay clean.  It is
silent when ``enabled`` is False (library default for short work) and when stderr is not
a terminal unless ``enabled=True`` is forced.
"""

from __future__ import annotations

import sys

__all__ = ["progress"]


def progress(total: int | None = None, desc: str = "", enabled: bool | None = None, unit: str = "it"):
    """A tqdm bar on stderr.

    Parameters
    ----------
    total : int, optional
        Number of steps (``bar.update(k)`` adds ``k``).
    desc : str
        Label shown before the bar.
    enabled : bool, optional
        ``None``: shown when stderr is a terminal; ``True``/``False`` force it.

    Returns
    -------
    tqdm.tqdm
        Use as a context manager or call ``close()``.
    """
    from tqdm import tqdm  # deferred: ~50 ms, only long work needs a bar

    disable = (not sys.stderr.isatty()) if enabled is None else (not enabled)
    return tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, disable=disable, leave=False,
                dynamic_ncols=True, mininterval=0.2)
