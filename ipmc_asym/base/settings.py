"""Every numerical knob of the toolkit, defined once (pure data).

Change a value here and every command, the scene planner, the bench and ``validate`` follow.
"""

from __future__ import annotations

import math

#: error estimate above which a closed form / quadrature result is outside its validity
VALIDITY_LIMIT = 1e-2

#: relative tolerance handed to scipy's solve_bvp on the residuals
BVP_TOL = 1e-10
#: the relative error the BVP states for I (measured ~1e-12 against the exact linear
#: solution and the closed forms, tests/bvp/test_solver.py): the stated bound is looser on purpose
BVP_STATED_ERROR = 1e-9
#: the relative error the ``exact`` fidelity states for I (measured <= 2.9e-12 against the
#: BVP on 1 um - 10 mm x +-(1e-4 - 20) V x 3 models, tests/kernels/test_exact.py)
EXACT_STATED_ERROR = 1e-11
#: maximum mesh nodes of one BVP solve
BVP_MAX_NODES = 300_000
#: looser solve_bvp tolerances tried, in order, when BVP_TOL cannot be met (rounding-limited
#: meshes where the layers overlap, e.g. total thickness 1 um at 20 V): I changes by < 1e-12
#: relative between 1e-10 and 1e-8 there (measured), inside BVP_STATED_ERROR
BVP_TOL_FALLBACK = (1e-9, 1e-8)
#: mesh-node cap of the attempts before the last one (a failing attempt stops early)
BVP_MAX_NODES_FIRST = 30_000

#: smallest TOTAL thickness 2e (m) the toolkit accepts.  The model is a continuum (mean-field
#: Poisson-Boltzmann) description of Nafion, whose hydrophilic ionic clusters are ~4-5 nm
#: across: below ~100 nm the film spans only ~20 clusters and the Debye length of the
#: constant model (~34 nm) is comparable to the film, so no rung (not even the BVP of the
#: same continuum equations) describes it; every command refuses at once (docs/design.md)
MIN_THICKNESS = 100e-9

#: largest length, TOTAL width and TOTAL thickness (m) of a strip: a numerical guard, not a physical
#: limit (IPMC strips are centimetres long; a bare `--thickness 200`, 200 m, still runs with its
#: plausibility warning).  At 1e308 m the charge Q = sigma 2l L and the bending stiffness overflow to
#: inf; 1 km keeps every product finite
MAX_DIMENSION = 1e3
#: smallest length and TOTAL width (m) of a strip, as a numerical guard (the thickness has its own floor,
#: MIN_THICKNESS): a subnormal length divides the beam's formulas by zero
MIN_DIMENSION = 1e-9

#: largest |voltage| (V) the toolkit is validated on (1e-4 - 20 V against the BVP).  The model
#: has blocking electrodes and no electrode reactions, while water electrolyses above ~1.23 V
#: (IPMCs are driven at a few volts): above this voltage every result carries a warning
VALIDATED_VOLTAGE = 20.0
#: the decomposition potential of water (V; the standard value at 25 C is 1.229 V): above it a real
#: electrode may electrolyse the solvent, which the model (blocking electrodes) leaves out; said in a
#: note beside the numbers, not a flag (IPMCs are driven at a few volts, as the paper's strips)
ELECTROLYSIS_VOLTAGE = 1.23

#: largest |phi0| (V) any command or library entry accepts (a Strip, the voltages of the moment
#: integral, the charge and a sweep; a time-domain drive): a numerical guard, not a physical
#: limit.  The charge kernels' closed forms lose finite values somewhere above ~1e100 V (measured:
#: NaN charge at a 1e200 V step), and near the overflow of A2 = F |phi0|/(R T) (~4e306 V) the
#: static charge's kernels do not return at all; 50x the validated range is far past any use and keeps
#: every output finite (tests/dynamics/test_waveforms.py, tests/integration/test_extremes.py); beyond
#: VALIDATED_VOLTAGE results still carry the warning
MAX_VOLTAGE = 1e3
#: the same cap, as the time-domain drives name it
MAX_DRIVE_VOLTAGE = MAX_VOLTAGE

#: the frequencies (Hz) a spectrum accepts: a numerical guard, not a physical limit (IPMCs are driven
#: at 0.01-100 Hz).  At 1e-300 Hz or 1e300 Hz the closed forms overflow; every output of the three
#: models, both methods and beams, with and without the electrode line, is finite on this range
#: (tests/dynamics/test_circuit.py)
FREQUENCY_RANGE = (1e-9, 1e12)

#: the cation diffusion coefficients D (m^2/s) a material accepts: a numerical guard, not a physical
#: limit (the plausible range, model.limits.PLAUSIBLE["D"], only warns).  Every dynamic time scales as
#: 1/D: at 1e308 the time constant underflows to 0 and at 1e-320 it overflows to inf; from one end to
#: the other of this range the time constant of every accepted strip stays a normal double, and step,
#: drive and freq return finite rows at both ends (tests/model/test_params.py)
DIFFUSION_RANGE = (1e-30, 1e10)

#: the mean cation concentrations C_moy (mol/m^3) a material accepts: a numerical guard, not a physical
#: limit (the plausible range, model.limits.PLAUSIBLE["c_moy"], only warns).  The Debye length goes as
#: C_moy^-1/2: at 1e-320 every rung fails (the BVP's Jacobian is singular); at both ends of this range
#: estimate, charge, step and freq return on strips from MIN_THICKNESS to MAX_DIMENSION thick
#: (tests/model/test_params.py)
C_MOY_RANGE = (1e-3, 1e8)

#: longest Kelvin-Voigt creep time tau_v = eta_E/E (s) of the beam: a numerical guard.  Past it the time
#: step's first-order-hold particular solution cancels to its last digits (tau_v dM/dt against the creep
#: it leaves: 3 % off an exact creep at tau_v = 8e4 s, 2e-4 at 8e3 s); at 1e3 s a strip creeps 1e-4 of its
#: way in 0.1 s, far past critical damping of every mode (the first at ~0.01 s on the nominal strip)
MAX_CREEP_TIME = 1e3

#: largest sheet resistance R_s (Ohm/sq) of an electrode: a numerical guard, not a physical limit (plated
#: Pt on Nafion measures ~1-100 Ohm/sq; 1e12 is an insulating film's).  At 1e308 the electrode line's
#: arrays overflow (step, drive: "array must not contain infs or NaNs"); up to this cap freq's outputs
#: are finite and step's line refuses in one line where its segments do not resolve it
MAX_SHEET_RESISTANCE = 1e12

#: shortest time span (s) a waveform's ramp time or period and a drive's duration may have: the period
#: of the highest frequency a spectrum accepts (FREQUENCY_RANGE), a numerical guard.  A subnormal ramp
#: time (1e-320 s) makes the ramp's slope V/TR overflow
MIN_TIME = 1.0 / FREQUENCY_RANGE[1]

#: longest output time of the transient PNP, in diffusion times e^2/D (its own time unit, the slowest of
#: the model: a step's strip is at rest after a few, and a waveform's cost grows with its periods).
#: solve_ivp's BDF cannot step past ~1e290 of them ("Required step size is less than spacing between
#: numbers", measured on the nominal strip and at D = 1e10); 1e12 is far past any use and far from that,
#: and at least 1e12 tau (e^2/D >= ~1.5 tau on every accepted strip), looser than the circuit's substeps
MAX_PNP_DIFFUSION_TIMES = 1e12

#: relative rounding floor of the error estimate of corrected / quadrature (the two terms are
#: assembled with cancellations; measured <= 2.3e-12 against the BVP on 1 um - 10 mm x 0.1 mV - 20 V)
ROUNDING_ERROR = 1e-11

DEFAULT_SCENE_TOL = 1e-3

#: default face strain ``e|kappa|`` above which the small-strain (linear elastic) beam model is
#: not assumed to hold (``Material.strain_limit``, a model assumption: rows above it are kept
#: and flagged).  No source read states hydrated Nafion's proportional limit or yield strain
#: as a number (searched: tensile studies of hydrated Nafion 117/212 describe a linear region
#: that shrinks with water uptake, without a value we could read); 1 % is a stated default,
#: settable per material (``--strain-limit``, scene ``[material] strain_limit``)
STRAIN_LIMIT = 1e-2
STRAIN_LIMIT_SOURCE = ("stated default, no measured proportional limit of hydrated Nafion read; "
                       "set Material.strain_limit / --strain-limit from your own tensile data")

#: a scaling law "holds" where the local exponent is within this of the law's exponent
LAW_HOLD_TOL = 0.05

#: the concentration thresholds of the layer widths (profiles, validate, scenes)
DEVOID_LEVEL = 0.01      # C_bar rises through this: the paper's "presque totalement depourvue"
DEPLETION_LEVEL = 0.5    # C_bar rises through half the mean concentration
ACCUMULATION_FRACTION = math.exp(-1.0)   # the excess C_bar - 1 falls to 1/e of its face value
ACCUMULATION_HALF_FRACTION = 0.5         # ... or to half of it

#: sweeps: refuse more rows than this unless --max-rows says otherwise; rows per chunk
MAX_ROWS = 10**7
#: 2^16 rows of a sweep chunk are 20 MB (306-byte rows): under glibc's largest mmap threshold
#: (32 MB), so malloc recycles a freed chunk's memory instead of mapping and page-faulting a
#: fresh one each chunk (2^18 rows, 80 MB: ~30 ms of faults a chunk); a 10^6-row CSV sweep
#: went from 2.2-2.5 s to 1.9 s (measured, this machine)
CHUNK_ROWS = 2**16

#: hard ceilings of the settable caps (``--max-rows``, ``--max-samples``, ...): a cap raised past its
#: ceiling is refused in one line, so that no setting of a cap lets memory or time run away.
#: sweep rows: streamed in CHUNK_ROWS chunks (memory bounded), ~1.9 s per 1e6 rows to CSV (measured,
#: above): 1e9 rows are ~30 min and a ~300 GB file
MAX_ROWS_CEILING = 10**9
#: fit data rows: held in memory and read by every evaluation of the fit; a row is a few numbers, so
#: the 64 MiB input cap (base.inputs) holds about this many: 10 times the default cap
MAX_DATA_ROWS_CEILING = 10**6
#: uq model runs: streamed chunk by chunk (memory does not grow), ~1e6 runs/s at leading in one
#: process: 1e9 runs are ~17 min, 10 times the default cap
MAX_SAMPLES_CEILING = 10**9
#: uq runs kept for --out and --plot, ~100 B each in memory: 2e7 are ~2 GB, 10 times the default cap
MAX_STORE_SAMPLES_CEILING = 2 * 10**7
#: fit's extra starts, each a full least-squares solve (seconds on a time series): 1e4 are hours,
#: 10 times the default cap
MAX_MULTISTART_CEILING = 10**4
#: figure resolution: a page-wide figure (17 cm x ~15 cm) is ~1 GB of RGBA pixels at 2400 dpi (the
#: resolution of image-setters), 4 times the default cap
MAX_DPI_CEILING = 2400
#: output points of step and freq: held in memory with every column (~100-200 B a point with the
#: beam's outputs): 1e6 points are ~0.2 GB, 10 times the default cap
MAX_POINTS_CEILING = 10**6
#: one input file (--max-input-size, bytes): read whole into memory and parsed there (the text and its
#: parsed rows or tables take several times the file's size); a fit's MAX_DATA_ROWS_CEILING rows are
#: ~50 MB of CSV: 1 GiB is 16 times the default cap (base.inputs.MAX_INPUT_BYTES, 64 MiB)
MAX_INPUT_BYTES_CEILING = 2**30

#: beam regimes outside the model (fits leave these points out)
OUTSIDE_REGIMES = ("past-quarter-turn", "multi-turn")

# Interpreted twins (``_jit.interpreted``, ``integral.interpret_small``): in a one-shot command
# a handful of points is cheaper interpreted than after loading the compiled driver from the
# cache (~0.5 s in a fresh process): interpret while points x the rung's interpreted cost per
# point (``registry.FIDELITIES[...].interpreted_s``) stays within this budget.
INTERPRET_BUDGET_S = 0.05
