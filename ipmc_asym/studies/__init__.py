"""Studies built on the forward model: sweeps and power-law fits, profiles, scenes, scaling
laws, charge studies, calibration and uncertainty quantification."""
