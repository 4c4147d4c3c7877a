"""Vectorised element matrices (one batched computation for all elements of a kind)."""
