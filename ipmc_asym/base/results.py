"""What every public result type shares: a one-screen summary, ``.plot()`` and ``.to_xarray()``.

A result class lists its arrays in a :class:`ResultSpec` (which fields lie along which
dimension, which are plotted against which, which numbers go in the summary) and inherits
:class:`ResultMixin`; the units and long names come from the output vocabulary
(:mod:`ipmc_asym.base.quantities`), one table for the text, CSV, NetCDF and plot labels.  It
lives in ``base/`` so that the results of every layer (``bvp``, ``integral``, ``forward``,
``dynamics``, ``studies``) can use it: the figures are generic, built from the spec, on a bare
Matplotlib ``Figure`` (no pyplot state, no backend selected).
"""

from __future__ import annotations

import textwrap
from typing import NamedTuple

import numpy as np

from ipmc_asym.base.quantities import BY_NAME

__all__ = ["Panel", "ResultSpec", "ResultMixin", "label", "units_of"]


class Panel(NamedTuple):
    """One axes of :meth:`ResultMixin.plot`: data variables ``ys`` against ``x``.

    Attributes
    ----------
    x : str   data variable or the dimension on the horizontal axis (vocabulary name)
    ys : tuple of str   data variables on the vertical axis (one unit per panel)
    xlog, ylog : bool   logarithmic axes (magnitudes of a complex variable are plotted)
    kind : str   "line" or "hist" (a histogram of ``ys``; ``x`` is then unused)
    """

    x: str
    ys: tuple
    xlog: bool = False
    ylog: bool = False
    kind: str = "line"


class ResultSpec(NamedTuple):
    """How a result class maps onto a labelled dataset and a figure.

    Attributes
    ----------
    dim : str   name of the dimension the arrays lie along ("t", "f", "z", "point", ...)
    coord : str or None   field holding that dimension's values (None: an index)
    fields : tuple of str   array fields along ``dim`` (data variables)
    panels : tuple of Panel   the figure, one axes per panel (vocabulary names)
    scalars : tuple of str   number fields shown in the summary and kept as dataset attributes
    names : dict   field -> vocabulary name where the two differ (``{"phi0": "voltage"}``)
    labels : tuple of str   array fields that label the points (the inputs: ``thickness``,
        ``voltage``): coordinates along ``dim`` in :meth:`ResultMixin.to_xarray`, not data
    """

    dim: str
    coord: str | None
    fields: tuple
    panels: tuple = ()
    scalars: tuple = ()
    names: dict = {}
    labels: tuple = ()


def units_of(name: str) -> tuple[str, str]:
    """``(unit, long_name)`` of a vocabulary name; ``ValueError`` for a name outside it."""
    q = BY_NAME.get(name)
    if q is None:
        raise ValueError(f"result variable {name!r} is not in the output vocabulary (base/quantities.py)")
    return q.unit, q.long_name


def label(name: str, magnitude: bool = False) -> str:
    """Axis label with the unit in brackets (``[1]`` for a dimensionless quantity)."""
    unit, long_name = units_of(name)
    text = f"|{long_name}|" if magnitude else long_name
    return f"{text} [{unit}]" if unit else text


def _fmt(v) -> str:
    if isinstance(v, (bool, np.bool_)):
        return str(bool(v))
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.6g}"
    if isinstance(v, (complex, np.complexfloating)):
        return f"{complex(v):.4g}"
    return repr(v)


def _range(a: np.ndarray) -> str:
    if a.dtype.kind == "b":
        return str(bool(a)) if a.ndim == 0 else f"{int(a.sum())} of {a.size} true"
    if a.dtype.kind not in "fciu":
        vals = list(dict.fromkeys(str(v) for v in a.reshape(-1)))
        return ", ".join(vals[:4]) + (", ..." if len(vals) > 4 else "")
    mag = np.abs(a) if a.dtype.kind == "c" else a
    fin = mag[np.isfinite(mag)]
    if fin.size == 0:
        return "no finite value"
    lo, hi = float(fin.min()), float(fin.max())
    rng = f"{lo:.4g}" if lo == hi else f"{lo:.4g} .. {hi:.4g}"
    return ("|.| " if a.dtype.kind == "c" else "") + rng


class ResultMixin:
    """Summary ``repr``, :meth:`plot`, :meth:`to_xarray` and :meth:`to_dataframe` from ``_result``.

    A subclass sets ``_result`` (a :class:`ResultSpec`) and, where its arrays are not plain
    fields, overrides :meth:`_arrays`.  The dataclass of a result passes ``repr=False`` so
    that this summary is its ``repr``.
    """

    _result: ResultSpec

    #: string fields shown on the summary's first line where the class has them
    _HEADLINE = ("model", "fidelity", "method", "output", "beam", "success")

    # ---- data ---------------------------------------------------------------------------
    def _arrays(self) -> tuple[str, np.ndarray | None, dict]:
        """``(dim, coordinate values or None, {vocabulary name: array})`` of the result."""
        spec = self._result
        out = {}
        for f in spec.labels + spec.fields:
            # "inputs.voltage": the key of a dict field
            head, _, key = f.partition(".")
            v = getattr(self, head, None)
            v = v.get(key) if key and isinstance(v, dict) else v
            if v is None:
                continue
            out[spec.names.get(f, f)] = np.asarray(v)
        coord = None if spec.coord is None else np.asarray(getattr(self, spec.coord))
        return spec.dim, coord, out

    def _varying_label(self, arrays: dict, n: int):
        """``(name, values)`` of the first label (an input, :attr:`ResultSpec.labels`) that is 1-D
        of ``n`` values and not constant, or None."""
        for name in self._result.labels:
            v = arrays.get(name)
            if v is not None and v.ndim == 1 and v.size == n and n > 1 and np.ptp(v) > 0:
                return name, v
        return None

    def _panels(self, arrays: dict) -> tuple:
        """The panels of :meth:`plot` (the spec's; a result whose outputs vary overrides it)."""
        return self._result.panels

    def _scalars(self) -> dict:
        spec = self._result
        out = {}
        for f in spec.scalars:
            v = getattr(self, f, None)
            if isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool):
                out[spec.names.get(f, f)] = float(v)
        return out

    def _headline(self) -> str:
        parts = []
        for k in self._HEADLINE:
            v = getattr(self, k, None)
            if isinstance(v, (str, bool, np.bool_)) and v != "":
                parts.append(f"{k}={v}")
        return f"{type(self).__name__}({', '.join(parts)})"

    # ---- summary ------------------------------------------------------------------------
    def __repr__(self) -> str:
        dim, coord, arrays = self._arrays()
        lines = [self._headline()]
        if coord is not None:
            lines.append(f"  {dim:<24} {coord.size} values, {_range(coord)} [{units_of(dim)[0]}]")
        for name, a in arrays.items():
            if name == dim:
                continue
            unit = units_of(name)[0]
            shape = "x".join(str(n) for n in a.shape) or "scalar"
            extent = BY_NAME[name].extent  # which thickness or width is meant: total, never the half
            shown = f"{name} ({extent})" if extent else name
            lines.append(f"  {shown:<24} {shape:>8}  {_range(a)}" + (f" [{unit}]" if unit else ""))
        for name, v in self._scalars().items():
            unit = units_of(name)[0]
            lines.append(f"  {name:<24} = {_fmt(v)}" + (f" {unit}" if unit not in ("", "1") else ""))
        msg = getattr(self, "message", "")
        if isinstance(msg, str) and msg:
            lines.append(f"  message: {msg if len(msg) <= 200 else msg[:197] + '...'}")
        return "\n".join(lines[:40])

    # ---- labelled forms -----------------------------------------------------------------
    def to_xarray(self):
        """The result as an ``xarray.Dataset``: every array a data variable along the result's
        dimension, with ``units`` and ``long_name`` from the output vocabulary; the scalars are
        attributes.  Needs xarray.
        """
        import xarray as xr  # deferred: heavy import, an optional dependency

        dim, coord, arrays = self._arrays()
        data, n = {}, None if coord is None else coord.size
        for name, a in arrays.items():
            if name == dim:
                continue
            if a.ndim == 0:
                dims = ()
            elif a.ndim == 1:
                dims = (dim,)
            else:
                dims = (dim,) + tuple(f"{dim}_{i}" for i in range(1, a.ndim))
            if a.dtype.kind not in "fciub":
                a = a.astype(str)
            unit, long_name = units_of(name)
            data[name] = xr.Variable(dims, a, attrs={"units": unit, "long_name": long_name})
            if a.ndim and n is None:
                n = a.shape[0]
        # the inputs that label the points are coordinates, so that .sel and plots read them
        coords = {name: data.pop(name) for name in self._result.labels if name in data}
        if n is not None:
            values = np.arange(n) if coord is None else coord
            unit, long_name = units_of(dim)
            coords[dim] = xr.Variable((dim,), values, attrs={"units": unit, "long_name": long_name})
        attrs = {"result": type(self).__name__}
        for k in ("model", "fidelity", "method", "output", "beam"):
            v = getattr(self, k, None)
            if isinstance(v, str):
                attrs[k] = v
        attrs.update(self._scalars())
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def to_dataframe(self):
        """The arrays along the result's dimension as a ``pandas.DataFrame`` (one row per
        point; needs xarray and pandas).  The units are in ``df.attrs["units"]``."""
        ds = self.to_xarray()
        dim = self._result.dim
        one_d = [k for k, v in ds.data_vars.items() if v.dims == (dim,)]
        df = ds[one_d].to_dataframe()
        df.attrs["units"] = {k: ds[k].attrs["units"] for k in one_d}
        return df

    # ---- figure -------------------------------------------------------------------------
    def plot(self, *, figsize=(6.4, 4.8)):
        """A Matplotlib ``Figure`` of the result (one axes per panel of its spec), built without
        pyplot: ``fig.savefig(path)`` writes it; in a notebook it displays itself."""
        from matplotlib.backends.backend_agg import FigureCanvasAgg  # deferred: matplotlib (start-up)
        from matplotlib.figure import Figure  # deferred: matplotlib (start-up)

        dim, coord, arrays = self._arrays()
        panels = self._panels(arrays)
        fig = Figure(figsize=(figsize[0], max(figsize[1], 2.4 * len(panels))), layout="constrained")
        FigureCanvasAgg(fig)
        axes = fig.subplots(len(panels), 1, squeeze=False)[:, 0]
        for ax, panel in zip(axes, panels):
            self._draw(ax, panel, dim, coord, arrays)
        fig.suptitle(textwrap.fill(self._headline(), 80), fontsize="small")  # a long headline kept in the figure
        return fig

    def _draw(self, ax, panel: Panel, dim, coord, arrays) -> None:
        present = [y for y in panel.ys if y in arrays]
        if panel.kind == "hist":
            for y in present:
                v = np.asarray(arrays[y], float).reshape(-1)
                ax.hist(v[np.isfinite(v)], bins=30, histtype="step", label=units_of(y)[1])
            ax.set_xlabel(label(present[0]) if present else "")
            ax.set_ylabel(label("count"))
        else:
            xname = panel.x
            if panel.x == dim:
                first = np.atleast_1d(arrays[present[0]] if present else next(iter(arrays.values())))
                x = np.arange(first.shape[0]) if coord is None else coord
                if coord is None:  # numbered points: against the input that varies along them, if one does
                    xname, x = self._varying_label(arrays, first.shape[0]) or (xname, x)
            else:
                x = arrays[panel.x]
            x = np.asarray(x).reshape(-1)
            # points in the order of an input along them (a line through unsorted points zigzags)
            order = np.argsort(x, kind="stable") if xname != panel.x else slice(None)
            x = x[order]
            cplx = any(arrays[y].dtype.kind == "c" for y in present)
            for k, y in enumerate(present):
                v = np.asarray(arrays[y])
                v = (np.abs(v) if v.dtype.kind == "c" else v).astype(float).reshape(x.size, -1)[order]
                if panel.ylog:
                    v = np.abs(v)
                # a style per quantity: the lines of a panel told apart in grayscale too
                ax.plot(x, v, linestyle=("-", "--", ":", "-.")[k % 4], marker="." if x.size < 30 else None,
                        label=units_of(y)[1])
            ax.set_xlabel(label(xname))
            # wrapped: a long name on one line runs past a panel's height into its neighbours
            # an equation ("z = -e") kept on one line: its spaces made non-breaking
            ax.set_ylabel(textwrap.fill(label(present[0], magnitude=cplx).replace(" = ", "\u00a0=\u00a0"), 32)
                          if present else "")
            if panel.xlog or (xname != panel.x and x.size > 2 and x[0] > 0 and x[-1] / x[0] > 100):
                ax.set_xscale("log")  # an input spanning decades (thickness 10 um .. 1 mm)
            if panel.ylog:
                ax.set_yscale("log")
        if len(present) > 1:
            ax.legend(fontsize="small")
        if not present:
            ax.text(0.5, 0.5, "nothing to plot", ha="center", va="center", transform=ax.transAxes)
