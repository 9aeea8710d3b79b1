"""Files and formats: atomic writes and output-path checks, the compiled text formatter,
labelled datasets (xarray/NetCDF)."""
