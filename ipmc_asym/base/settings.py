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

#: beam regimes outside the model (fits leave these points out)
OUTSIDE_REGIMES = ("past-quarter-turn", "multi-turn")

# Interpreted twins (``_jit.interpreted``, ``integral.interpret_small``): in a one-shot command
# a handful of points is cheaper interpreted than after loading the compiled driver from the
# cache (~0.5 s in a fresh process): interpret while points x the rung's interpreted cost per
# point (``registry.FIDELITIES[...].interpreted_s``) stays within this budget.
INTERPRET_BUDGET_S = 0.05
