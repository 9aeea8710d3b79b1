"""Benchmark of speed and accuracy (``ipmc-asym bench``)."""
