"""
A sweep on a Dask cluster
=========================

A sweep is cut into chunks of contiguous rows, each chunk a task; on a Dask cluster the chunks
run on its workers and are put back in order, so the rows are those of the serial sweep, bit
for bit. It pays where a point is expensive and the rows are many: here, small enough for the
documentation build, the full BVP at 8 voltages and two thicknesses, on a ``LocalCluster`` of
two single-threaded worker processes (on your own cluster pass
``distributed.Client("tcp://SCHEDULER:8786")``, or ``--scheduler`` on the command line). Each
worker loads the compiled kernels once, from the on-disk cache. The time on the cluster
includes the workers' start (a few seconds), so on so few rows, or on a busy machine, it can
exceed the serial time; the rows are the same either way.
"""

import time

import matplotlib.pyplot as plt
import numpy as np
from distributed import Client, LocalCluster

from ipmc_asym.studies.sweep_chunks import sweep_chunked

vary = {"thickness": np.array([100e-6, 200e-6]), "voltage": np.geomspace(0.05, 2.0, 8)}  # TOTAL thickness 2e

t0 = time.perf_counter()
serial = sweep_chunked(vary, None, model="constant", fidelity="bvp")
t_serial = time.perf_counter() - t0

with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
        Client(cluster) as client:
    t0 = time.perf_counter()
    rows = sweep_chunked(vary, client, model="constant", fidelity="bvp")
    t_cluster = time.perf_counter() - t0

same = all(np.array_equal(rows[k], serial[k], equal_nan=True) for k in ("I", "w", "F_block"))
print(f"{rows.size} BVP rows: serial {t_serial:.2f} s, 2 workers {t_cluster:.2f} s "
      f"(including the workers' start); identical to the serial rows: {same}")

# %%
fig, ax = plt.subplots(figsize=(6, 3.8))
for th, mk in zip(vary["thickness"], ("o", "s")):
    r = rows[rows["thickness"] == th]
    ax.plot(r["voltage"], np.abs(r["F_block"]) * 1e3, marker=mk, mfc="white",
            label=f"total thickness 2e = {th * 1e6:g} µm")
ax.set_xscale("log")
ax.set_xlabel("voltage φ0 [V]")
ax.set_ylabel("blocking force |F| [mN]")
ax.set_title("constant model, full BVP at every point, on 2 Dask workers", fontsize=10)
ax.grid(alpha=0.3)
ax.legend(fontsize=8)
fig.tight_layout()
plt.show()
