"""Reduced nonlinear-capacitor model (placeholder, filled below)."""
