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
#: solution and the closed forms, tests/test_bvp.py): the stated bound is looser on purpose
BVP_STATED_ERROR = 1e-9
#: the relative error the ``exact`` fidelity states for I (measured <= 2.9e-12 against the
#: BVP on 1 um - 10 mm x +-(1e-4 - 20) V x 3 models, tests/test_exact.py)
EXACT_STATED_ERROR = 1e-11
#: maximum mesh nodes of one BVP solve
BVP_MAX_NODES = 300_000

#: default relative tolerance of a scene and of the "small displacement" beam regime
DEFAULT_TOL = 1e-2
DEFAULT_SCENE_TOL = 1e-3

#: a strain above this at the faces is outside linear elasticity (beam check)
STRAIN_LIMIT = 1e-2

#: a scaling law "holds" where the local exponent is within this of the law's exponent
LAW_HOLD_TOL = 0.05

#: the concentration thresholds of the layer widths (profiles, validate, scenes)
DEVOID_LEVEL = 0.01      # C_bar rises through this: the paper's "presque totalement depourvue"
DEPLETION_LEVEL = 0.5    # C_bar rises through half the mean concentration
ACCUMULATION_FRACTION = math.exp(-1.0)   # the excess C_bar - 1 falls to 1/e of its face value
ACCUMULATION_HALF_FRACTION = 0.5         # ... or to half of it

#: sweeps: refuse more rows than this unless --max-rows says otherwise; rows per chunk
MAX_ROWS = 10**7
CHUNK_ROWS = 2**18

#: beam regimes outside the model (fits leave these points out)
OUTSIDE_REGIMES = ("past-quarter-turn", "multi-turn")
