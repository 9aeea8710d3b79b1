"""Files and formats: atomic writes and output-path checks, JSON, the compiled text
formatter, labelled datasets (xarray/NetCDF)."""
