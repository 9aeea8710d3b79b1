"""Bench section ``dynamics``: ``freq`` with 1000 frequencies (beam dynamics on; and with the electrode
sheet resistance, the distributed moment driving the modes) and a 10^5-point sine
response at circuit fidelity (the drive run: circuit, the forward model's mechanics per time point,
the modal beam), measured side by side in one run (CPU time, one Numba thread)."""

from __future__ import annotations

import numpy as np

from ipmc_asym import drive_response, frequency_response, line_response
from ipmc_asym_bench.timing import cpu_best, load, threads

__all__ = ["section", "TARGETS"]

#: seconds (the project's goals)
TARGETS = {"freq_1000_s": 0.05, "freq_1000_line_s": 0.05, "sine_1e5_quasi_static_s": 0.5, "sine_1e5_dynamic_s": 0.5}


def _best(fn, repeats):
    with threads(1):
        return cpu_best(fn, repeats)


def section(quick: bool = False) -> dict:
    """The ``dynamics`` bench section (see the module docstring)."""
    reps = 1 if quick else 3
    f = np.geomspace(1e-2, 1e4, 1000)
    frequency_response(f[:10], method="circuit", beam="dynamic")
    drive_response("sine:1V@10Hz", 0.05, 5001)  # compile / load the kernels once
    n = 10**4 if quick else 10**5
    r = {
        "freq_1000_s": _best(lambda: frequency_response(f, method="circuit", beam="dynamic"), 5 * reps),
        "freq_1000_line_s": _best(lambda: line_response(f, method="circuit", beam="dynamic", sheet_resistance=2.5),
                                  5 * reps),
        "sine_1e5_quasi_static_s": _best(lambda: drive_response("sine:1V@10Hz", 1.0, n, beam="quasi-static"), reps),
        "sine_1e5_dynamic_s": _best(lambda: drive_response("sine:1V@10Hz", 1.0, n, beam="dynamic"), reps),
    }
    what = {"freq_1000_s": "freq, 1000 frequencies, circuit, beam dynamics (free and blocked tip)",
            "freq_1000_line_s": "freq, 1000 frequencies, circuit, beam dynamics, electrode sheet resistance 2.5 Ohm/sq",
            "sine_1e5_quasi_static_s": f"drive sine 10 Hz, {n} time points, circuit, quasi-static beam",
            "sine_1e5_dynamic_s": f"drive sine 10 Hz, {n} time points, circuit, beam dynamics"}
    figs = [{"what": what[k], "value": r[k], "unit": "s", "target": TARGETS[k], "pass": bool(r[k] <= TARGETS[k]),
             "note": f"CPU time, 1 thread, least of the repeats, load {load():.2f}" + (" (quick: 10^4 points)" if quick else "")}
            for k in TARGETS]
    return {"figures": figs}
