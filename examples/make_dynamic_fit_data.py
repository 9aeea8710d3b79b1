"""Regenerate ``dynamic_step.csv`` and ``dynamic_spectrum.csv`` (the dynamic-fit gallery example's data).

One strip (the nominal one: L = 2 cm, 2l = 5 mm, 2e = 200 µm, constant permittivity) with
D = 3e-10 m^2/s and C_moy = 2600 mol/m^3 (the "truth" the example recovers; neither is a
measured value): a 0.5 V step written by ``ipmc-asym step --out`` as it is (its columns,
per-area units and signs; the model's own columns dropped) and an impedance spectrum written
from ``ipmc-asym freq --json``'s ``Z_abs``, ``Z_phase`` (deg), with seeded noise: 2 % of each time
column's root mean square, 1 % on ``|Z|`` and 0.01 rad on the phase.

Run from the repository root: ``python examples/make_dynamic_fit_data.py``.
"""

import contextlib
import csv
import io
import json
import pathlib
import tempfile

import numpy as np

from ipmc_asym.cli import main

HERE = pathlib.Path(__file__).resolve().parent
TRUTH = ["--diffusion", "3e-10", "--c-moy", "2600"]


def step_file(rng):
    with tempfile.TemporaryDirectory() as d:
        out = pathlib.Path(d) / "step.csv"
        assert main(["step", "--voltage", "0.5V", "--duration", "50ms", "--points", "41", *TRUTH,
                     "--out", str(out)]) == 0
        with open(out, newline="") as fh:
            rows = list(csv.reader(fh))
    head = rows[0]
    keep = ["t", "phi0", "current_density", "w"]
    data = np.array([[float(r[head.index(c)]) for c in keep] for r in rows[2:]])  # t > 0
    for j in (2, 3):
        data[:, j] += 0.02 * np.sqrt(np.mean(data[:, j] ** 2)) * rng.standard_normal(len(data))
    with open(HERE / "dynamic_step.csv", "w", newline="") as fh:
        wr = csv.writer(fh)
        wr.writerow(keep)
        wr.writerows([[f"{x:.6g}" for x in r] for r in data])


def spectrum_file(rng):
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["freq", "--from", "0.1Hz", "--to", "100kHz", "--points", "25", *TRUTH, "--json"]) == 0
    doc = json.loads(buf.getvalue())
    f, za, zp = (np.asarray(doc[c], dtype=float) for c in ("f", "Z_abs", "Z_phase"))
    za = za * (1.0 + 0.01 * rng.standard_normal(f.size))
    zp = zp + np.degrees(0.01 * rng.standard_normal(f.size))
    with open(HERE / "dynamic_spectrum.csv", "w", newline="") as fh:
        wr = csv.writer(fh)
        wr.writerow(["f", "Z_abs", "Z_phase"])
        wr.writerows([[f"{a:.6g}", f"{b:.6g}", f"{c:.6g}"] for a, b, c in zip(f, za, zp)])


if __name__ == "__main__":
    rng = np.random.default_rng(2026)
    step_file(rng)
    spectrum_file(rng)
