"""The full nonlinear boundary-value problem across the thickness (paper §4, eqs (19)-(23)),
solved by SciPy: problem definitions, mesh and initial guess, and the driver.

``from ipmc_asym.bvp import solve`` keeps working: the driver's public names are here."""

from ipmc_asym.bvp.solver import *  # noqa: F401,F403
from ipmc_asym.bvp.solver import __all__  # noqa: F401
