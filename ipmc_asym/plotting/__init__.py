"""All matplotlib code of the toolkit: one module per topic; nothing below imports matplotlib.

:func:`pyplot` selects the Agg backend once and returns ``matplotlib.pyplot``;
:func:`savefig` writes a figure atomically (temp file in the same directory, then rename)
and closes it.
"""

from __future__ import annotations

from ..fileio import atomic_path

__all__ = ["pyplot", "savefig", "MODEL_COLOURS"]

#: one colour per permittivity model, in every figure
MODEL_COLOURS = {"constant": "C0", "linear": "C1", "affine": "C2"}


def pyplot():
    """``matplotlib.pyplot`` on the non-interactive Agg backend."""
    import matplotlib  # deferred: matplotlib is heavy and only figures need it

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def savefig(fig, path, **kw) -> str:
    """Save ``fig`` to ``path`` atomically and close it; returns the path."""
    import os

    fmt = kw.pop("format", None) or os.path.splitext(os.fspath(path))[1].lstrip(".") or "png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, **kw)
    pyplot().close(fig)
    return os.fspath(path)
