"""The registry of the bench's further sections and the caps of its sizes (light: no Numba,
read by ``--help`` and the option checks).

:data:`SECTIONS`: name -> ``"module:function"`` (imported only when run).  Each function takes
``quick: bool`` and returns ``{"figures": [{"what", "value", "unit", "target", "pass", "note"},
...], ...}``: figures measured side by side in one run, as ratios where a target is a ratio.
Adding a section is adding one line here.
"""

from __future__ import annotations

__all__ = ["SECTIONS", "MAX_POINTS", "MAX_BVP_POINTS"]

#: caps of ``--points`` and ``--bvp-points`` (memory: ~6 arrays of N doubles, 0.5 GB at the cap;
#: time: a BVP solve is ~0.05-0.1 s, three models)
MAX_POINTS = 10**7
MAX_BVP_POINTS = 200

SECTIONS: dict[str, str] = {
    # first: fresh-process wall times, measured before the dask section (after it, the same
    # sweep measured 3.6 s instead of 2.9 s: what the cluster leaves behind is not the sweep's)
    "commands": "ipmc_asym_bench.commands:section",  # sweep --out 10^6 rows, figures
    "exact_api": "ipmc_asym_bench.exact:section",
    "uq": "ipmc_asym_bench.uq:section",
    "distributed": "ipmc_asym_bench.distributed:section",
    "charge": "ipmc_asym_bench.charge:section",  # charge, step circuit/pnp
    "dynamics": "ipmc_asym_bench.dynamics:section",  # freq 1000 frequencies, 10^5-point sine drive
}
