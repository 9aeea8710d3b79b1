"""The physical model's inputs: material, strip geometry and drive, permittivity models, and
the dimensionless groups derived from them (paper §4, eqs (16)-(23))."""
