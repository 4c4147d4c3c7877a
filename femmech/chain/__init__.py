"""Chains of identical mechanisms on a main shaft (seed 5.1, Bild 5.1).

* :mod:`.model`: the chain (shaft nodes, segments, ends, N phased units), assembled M, B, C.

Stage 6 (chain): may import analysis, coupling, reduction, mechanisms, fe, solve.
"""

from femmech.chain.model import Chain, End, chain, follower_unit, torsion_segment

__all__ = ["Chain", "End", "chain", "follower_unit", "torsion_segment"]
