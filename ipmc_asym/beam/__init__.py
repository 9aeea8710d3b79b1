"""The cantilever (paper §3, eqs (7)-(15)): rotation, tip deflection and position, blocking
force, in small and large displacements, from the bending moment.

``from ipmc_asym.beam import solve_beam`` keeps working: the statics' public names are here."""

from ipmc_asym.beam.statics import *  # noqa: F401,F403
from ipmc_asym.beam.statics import __all__  # noqa: F401
