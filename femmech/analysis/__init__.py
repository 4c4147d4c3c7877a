"""Analyses: modes, sweeps, stability, response."""
