"""All matplotlib code of the toolkit: one module per topic; nothing below imports matplotlib.

:func:`pyplot` returns an object with ``subplots`` and ``close`` like ``matplotlib.pyplot``,
making :class:`matplotlib.figure.Figure` objects without pyplot: no backend is selected or
switched (a notebook user's backend stays as it is) and no figure enters pyplot's registry.
:func:`savefig` writes a figure atomically (temp file in the same directory, then rename).
"""

from __future__ import annotations

import os

from ipmc_asym.io.fileio import atomic_path

__all__ = ["pyplot", "savefig", "MODEL_COLOURS", "MODEL_LINES", "MODEL_MARKERS", "model_style"]

#: one colour per permittivity model, in every figure
MODEL_COLOURS = {"constant": "C0", "linear": "C1", "affine": "C2"}
#: ... and one line style and one marker, so that the models stay apart in black-and-white print
MODEL_LINES = {"constant": "-", "linear": "--", "affine": "-."}
MODEL_MARKERS = {"constant": "o", "linear": "s", "affine": "^"}


def model_style(model: str, *, line: bool = True, marker: bool = False, markevery=None) -> dict:
    """Matplotlib keywords of ``model``'s curves: its colour, and its line style and/or marker.

    ``line=False`` keeps a solid line (where the line style carries another meaning, e.g.
    small vs large displacement); ``marker=True`` adds the model's hollow marker every
    ``markevery`` points.
    """
    kw = {"color": MODEL_COLOURS.get(model, "k"), "ls": MODEL_LINES.get(model, "-") if line else "-"}
    if marker:
        kw.update(marker=MODEL_MARKERS.get(model, "o"), markevery=markevery, ms=4.5, mfc="white", mew=1.0)
    return kw


class _Figures:
    """The two pyplot functions the figures use, on bare :class:`matplotlib.figure.Figure`."""

    @staticmethod
    def subplots(nrows=1, ncols=1, *, figsize=None, dpi=None, **kw):
        from matplotlib.figure import Figure  # deferred: matplotlib is heavy and only figures need it

        fig = Figure(figsize=figsize, dpi=dpi)
        return fig, fig.subplots(nrows, ncols, **kw)

    @staticmethod
    def close(fig):
        """Nothing to release: the figure is not registered with pyplot."""


def pyplot():
    """Figure factory with pyplot's ``subplots``/``close`` signatures (no backend switch)."""
    return _Figures


def savefig(fig, path, **kw) -> str:
    """Save ``fig`` to ``path`` atomically and close it; returns the path."""

    fmt = kw.pop("format", None) or os.path.splitext(os.fspath(path))[1].lstrip(".") or "png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, **kw)
    pyplot().close(fig)
    return os.fspath(path)
