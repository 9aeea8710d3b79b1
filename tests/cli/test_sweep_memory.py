"""``sweep --out F.nc`` holds the grid in memory: its rows are capped so that memory stays under
1 GB, and a failed NetCDF write (a full disk) names the file.

The memory per row is measured (tracemalloc peak at two sizes: the growth per row, independent of
time and machine speed) and extrapolated to the cap.
"""

from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
import tracemalloc

import pytest
from references import REPO

from ipmc_asym.cli import main
from ipmc_asym.cli.sweep import MAX_MEMORY_ROWS

pytest.importorskip("xarray")
GB = 1024**3


def _peak(tmp_path, n):
    tracemalloc.start()
    try:
        rc = main(["sweep", "--vary", f"voltage=0.1V:2V:{n}", "--fidelity", "leading", "--no-progress",
                   "--out", str(tmp_path / f"s{n}.nc")])
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert rc == 0
    return peak


def test_nc_memory_at_the_cap_under_1_gb(tmp_path, capsys):
    _peak(tmp_path, 100)  # imports and compiled kernels loaded before measuring
    p1, p2 = _peak(tmp_path, 20000), _peak(tmp_path, 60000)
    per_row = (p2 - p1) / 40000
    assert 0 < per_row < 2000  # a few hundred bytes a row
    assert p1 + per_row * (MAX_MEMORY_ROWS - 20000) < GB, per_row


def test_nc_above_the_cap_refused_before_the_work(tmp_path, capsys):
    n = MAX_MEMORY_ROWS + 1
    rc = main(["sweep", "--vary", f"voltage=0.1V:2V:{n}", "--no-progress", "--out", str(tmp_path / "s.nc")])
    err = capsys.readouterr().err
    assert rc == 2 and "held in memory" in err and err.count("\n") == 1, err
    assert os.listdir(tmp_path) == []
    # streamed formats are not capped by it
    assert MAX_MEMORY_ROWS < 10**7


def _small_file_limit():
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG, as on a full disk
    resource.setrlimit(resource.RLIMIT_FSIZE, (64 * 1024, 64 * 1024))


def test_full_disk_while_writing_nc_names_the_path(tmp_path):
    pytest.importorskip("netCDF4")
    r = subprocess.run([sys.executable, "-m", "ipmc_asym", "sweep", "--vary", "voltage=0.1V:2V:20000", "--fidelity",
                        "leading", "--no-progress", "--out", "s.nc"], cwd=tmp_path, capture_output=True, text=True,
                       env={**os.environ, "PYTHONPATH": str(REPO)}, preexec_fn=_small_file_limit, timeout=600)
    assert r.returncode == 2, r.stderr[-2000:]
    assert "Traceback" not in r.stderr and "s.nc" in r.stderr.splitlines()[-1], r.stderr[-2000:]
    assert os.listdir(tmp_path) == []
