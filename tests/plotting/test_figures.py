import numpy as np
import pytest

from ipmc_asym.plotting.figures import make_all


# the dev loop draws the same figures once, as PDF, in the test below; this PNG pass runs in CI
@pytest.mark.slow
def test_figures_produced_and_nontrivial(tmp_path):
    import matplotlib.image as mpimg

    out = make_all(str(tmp_path), dpi=40, quick=True)
    pngs = [f for f in out["files"] if f.endswith(".png")]
    assert len(pngs) >= 8
    for f in pngs:
        img = mpimg.imread(f)
        assert img.shape[0] > 100 and img.shape[1] > 100
        assert np.std(img[..., :3]) > 0.02  # not uniform
        assert (tmp_path / f.split("/")[-1]).stat().st_size > 5000


def _same_style(handle, line):
    """A legend handle and a drawn line look alike: line style and marker; colour too unless the
    handle is the neutral gray that stands for "any model's colour"."""
    from matplotlib.colors import to_rgba

    if handle.get_linestyle() != line.get_linestyle() or handle.get_marker() != line.get_marker():
        return False
    return to_rgba(handle.get_color()) == to_rgba("0.35") or to_rgba(handle.get_color()) == to_rgba(line.get_color())


def _drawn(line):
    x, y = (np.asarray(v, float) for v in line.get_data())
    return line.get_visible() and bool(np.any(np.isfinite(x) & np.isfinite(y)))


@pytest.mark.slow  # ~11 s, every figure of the command: test_every_figure builds each one in the quick loop
def test_figures_command_writes_print_ready_vector_files(tmp_path, monkeypatch, capsys):
    """``figures --format pdf``: PDF files with no raster image in them; every figure one column
    (8.5 cm) or one page (17 cm) wide with every text >= 7 pt, and every legend entry the style of
    a curve actually drawn."""
    from matplotlib.text import Text

    import ipmc_asym.plotting as plotting
    import ipmc_asym.plotting.figures as pf
    import ipmc_asym.plotting.profiles as pp
    from ipmc_asym.cli import main

    figs = []

    def keep(fig, path, **kw):
        figs.append((path, fig))
        return plotting.savefig(fig, path, **kw)

    monkeypatch.setattr(pf, "savefig", keep)
    monkeypatch.setattr(pp, "savefig", keep)
    out = tmp_path / "figs"
    assert main(["figures", "--out", str(out), "--quick", "--format", "pdf"]) == 0
    capsys.readouterr()
    pdfs = sorted(out.glob("*.pdf"))
    assert len(pdfs) >= 10 and not list(out.glob("*.png"))
    for f in pdfs:
        data = f.read_bytes()
        assert data.startswith(b"%PDF") and b"/Subtype /Image" not in data, f.name
    assert len(figs) == len(pdfs)
    for path, fig in figs:
        w, _h = fig.get_size_inches()
        assert w <= 17.0 / 2.54 + 1e-9, (path, w)
        for t in fig.findobj(Text):
            if t.get_visible() and t.get_text():
                assert t.get_fontsize() >= 7.0, (path, t.get_text(), t.get_fontsize())
        lines = [ln for ax in fig.axes for ln in ax.get_lines() if _drawn(ln)]
        legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
        assert legends, path
        for leg in legends:
            for h, txt in zip(leg.legend_handles, leg.get_texts()):
                assert any(_same_style(h, ln) for ln in lines), (path, txt.get_text())


def test_legend_check_sees_an_entry_without_a_curve():
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    fig = Figure()
    ax = fig.subplots()
    ax.plot([0, 1], [0, 1], "-o", color="C0")
    ghost = Line2D([], [], color="0.35", ls=":", label="nothing drawn like this")
    lines = [ln for ln in ax.get_lines() if _drawn(ln)]
    assert not any(_same_style(ghost, ln) for ln in lines)
    assert any(_same_style(Line2D([], [], color="C0", ls="-", marker="o"), ln) for ln in lines)
