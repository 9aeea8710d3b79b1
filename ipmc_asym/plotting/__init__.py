"""All matplotlib code of the toolkit: one module per topic; nothing below imports matplotlib.

:func:`pyplot` returns an object with ``subplots`` and ``close`` like ``matplotlib.pyplot``,
making :class:`matplotlib.figure.Figure` objects without pyplot: no backend is selected or
switched (a notebook user's backend stays as it is) and no figure enters pyplot's registry.
:func:`savefig` writes a figure atomically (temp file in the same directory, then rename).
"""

from __future__ import annotations

import os
import re

from ipmc_asym.io.fileio import atomic_path

__all__ = ["pyplot", "savefig", "MODEL_COLOURS", "MODEL_LINES", "MODEL_MARKERS", "model_style", "COLUMN_WIDTH_IN",
           "PAGE_WIDTH_IN", "MIN_FONT_PT", "FORMATS", "MAX_FONT_PT", "check_figure_format", "print_fonts", "symbols"]

#: print layout: a figure is one journal column wide (8.5 cm) or, with side-by-side panels, a
#: page wide (17 cm); drawn at that size, so its fonts are what the page shows
COLUMN_WIDTH_IN = 8.5 / 2.54
PAGE_WIDTH_IN = 17.0 / 2.54
#: smallest and largest font on a printed figure (points): matplotlib's 10 pt default is a
#: poster size on a figure 8.5 cm wide
MIN_FONT_PT = 7.0
MAX_FONT_PT = 8.5
#: the formats every drawing command writes (``--format``; pdf and svg are vector)
FORMATS = ("png", "pdf", "svg")


#: code names in the vocabulary's long names -> the paper's symbols (mathtext), for plot labels
_SYMBOLS = (("M_A", "$M_A$"), ("theta", r"$\theta$"), ("phi0", r"$\varphi_0$"), ("C_moy", r"$C_{moy}$"),
            ("w_p", "$w_p$"), ("eps0", r"$\varepsilon_0$"), ("eps_moy", r"$\varepsilon_{moy}$"))


def symbols(label: str) -> str:
    """``label`` with the code names of quantities written as the paper's symbols."""
    for code, sym in _SYMBOLS:
        label = re.sub(rf"(?<![\w$]){re.escape(code)}(?![\w$])", lambda _m, s=sym: s, label)
    return label


def check_figure_format(fmt) -> str:
    """``fmt`` if it is one of :data:`FORMATS`, else a one-line ``ValueError``."""
    if fmt not in FORMATS:
        raise ValueError(f"format must be one of {', '.join(FORMATS)}; got {fmt!r}")
    return fmt


def print_fonts(fig, minimum: float = MIN_FONT_PT, maximum: float = MAX_FONT_PT) -> None:
    """Every text of ``fig`` (labels, ticks, legends, titles, notes) between ``minimum`` and
    ``maximum`` pt; call it before the layout (``tight_layout``) so the layout sees them."""
    from matplotlib.text import Text  # deferred: matplotlib is heavy and only figures need it

    for t in fig.findobj(Text):
        if t.get_text():
            t.set_fontsize(min(max(t.get_fontsize(), minimum), maximum))

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
    """Save ``fig`` to ``path`` atomically and close it; returns the path.

    Fonts are brought within :data:`MIN_FONT_PT` .. :data:`MAX_FONT_PT`; the format follows the extension
    (``format=`` overrides it).
    """

    fmt = kw.pop("format", None) or os.path.splitext(os.fspath(path))[1].lstrip(".") or "png"
    print_fonts(fig)
    # the tight box keeps every label and legend inside the file (nothing cut at an edge)
    kw.setdefault("bbox_inches", "tight")
    kw.setdefault("pad_inches", 0.03)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, **kw)
    pyplot().close(fig)
    return os.fspath(path)
