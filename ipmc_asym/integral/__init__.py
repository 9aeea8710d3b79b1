"""The moment integral ``I(e, phi0)`` (paper eq (27)) at every fidelity: the public API over
the compiled kernels, and the per-sample driver of the studies.

``from ipmc_asym.integral import moment_integral`` keeps working: the API's public names are
here."""

from ipmc_asym.integral.api import *  # noqa: F401,F403
from ipmc_asym.integral.api import __all__  # noqa: F401
