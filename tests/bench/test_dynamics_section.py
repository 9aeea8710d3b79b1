"""The bench section ``dynamics`` runs and reports its figures against the issue's targets."""

from ipmc_asym_bench.dynamics import TARGETS, section
from ipmc_asym_bench.suite import SECTIONS


def test_dynamics_section_quick():
    assert "dynamics" in SECTIONS
    r = section(quick=True)
    assert len(r["figures"]) == len(TARGETS)
    for f in r["figures"]:
        assert f["unit"] == "s" and f["value"] > 0 and f["pass"] == (f["value"] <= f["target"])
