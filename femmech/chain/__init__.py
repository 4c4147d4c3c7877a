"""Chains of identical mechanisms on a main shaft (seed 5.1, Bild 5.1).

* :mod:`.model`: the chain (shaft nodes, segments, ends, N phased units), assembled M, B, C.
* :mod:`.results`: ``ChainModes``, the result of every eigen-solution below.
* :mod:`.transfer`: stabilised transfer matrices with the Wittrick–Williams count
  (``transfer_modes``, ``count_below``) and the assembled reference (``assembled_modes``).
* :mod:`.sweep`: tracked sweeps over the drive angle by any method (``chain_sweep``,
  ``compare_methods``).
* :mod:`.cyclic`: uniform chains in closed form per wave number (``cyclic_modes``).
* :mod:`.continuum`: the smeared continuum (``continuum_modes`` with its error estimate,
  ``continuum_error_table``, ``validity_problems``).
* :mod:`.frame`: the chain's units on an elastic (reduced) machine frame (``mount_chain``).
* :mod:`.synthesis`: design parameters that keep the quasi-eigenfrequencies out of the
  drive harmonics (``synthesise``, ``resonance_margin``).

Stage 6 (chain): may import analysis, coupling, reduction, mechanisms, fe, solve.
"""

from femmech.chain.continuum import continuum_error_table, continuum_modes
from femmech.chain.cyclic import cyclic_modes, is_uniform, pass_bands
from femmech.chain.frame import guided_unit, mount_chain
from femmech.chain.model import Chain, End, chain, follower_unit, torsion_segment
from femmech.chain.results import ChainModes
from femmech.chain.sweep import chain_sweep, compare_methods
from femmech.chain.synthesis import (
    Parameter,
    SynthesisResult,
    resonance_margin,
    synthesise,
)
from femmech.chain.transfer import assembled_modes, count_below, transfer_modes

__all__ = ["guided_unit", "mount_chain", "Chain", "End", "chain", "follower_unit",
           "torsion_segment", "Parameter", "SynthesisResult", "resonance_margin", "synthesise",
           "cyclic_modes", "is_uniform", "pass_bands", "continuum_modes",
           "continuum_error_table", "ChainModes", "transfer_modes", "count_below",
           "assembled_modes", "chain_sweep", "compare_methods"]
