import numpy as np

from ipmc_asym.plotting.figures import make_all


def test_figures_produced_and_nontrivial(tmp_path):
    import matplotlib.image as mpimg

    out = make_all(str(tmp_path), dpi=40, quick=True)
    pngs = [f for f in out["files"] if f.endswith(".png")]
    assert len(pngs) >= 8
    for f in pngs:
        img = mpimg.imread(f)
        assert img.shape[0] > 100 and img.shape[1] > 300
        assert np.std(img[..., :3]) > 0.02  # not uniform
        assert (tmp_path / f.split("/")[-1]).stat().st_size > 5000
