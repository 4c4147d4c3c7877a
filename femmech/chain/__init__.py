"""Chains of identical mechanisms on a main shaft (seed 5.1, Bild 5.1).

* :mod:`.model`: the chain (shaft nodes, segments, ends, N phased units), assembled M, B, C.
* :mod:`.results`: ``ChainModes``, the result of every eigen-solution below.
* :mod:`.transfer`: stabilised transfer matrices with the Wittrick–Williams count
  (``transfer_modes``, ``count_below``) and the assembled reference (``assembled_modes``).
* :mod:`.sweep`: tracked sweeps over the drive angle by any method (``chain_sweep``,
  ``compare_methods``).
* :mod:`.cyclic`: uniform chains in closed form per wave number (``cyclic_modes``).
* :mod:`.continuum`: the smeared continuum (``continuum_modes`` with its error estimate,
  ``continuum_error_table``, ``validity_problems``), with :mod:`.impedance`, the
  impedance smearing of the units' exact dynamic stiffness.
* :mod:`.frame`: the chain's units on an elastic (reduced) machine frame (``mount_chain``).
* :mod:`.synthesis`: design parameters that keep the quasi-eigenfrequencies out of the
  drive harmonics (``synthesise``, ``resonance_margin``).

Stage 6 (chain): may import analysis, coupling, reduction, mechanisms, fe, solve.
"""

from femmech.deprecation import lazy_names

_LAZY = {
    "continuum_error_table": "femmech.chain.continuum",
    "continuum_modes": "femmech.chain.continuum",
    "cyclic_modes": "femmech.chain.cyclic",
    "is_uniform": "femmech.chain.cyclic",
    "pass_bands": "femmech.chain.cyclic",
    "guided_unit": "femmech.chain.frame",
    "mount_chain": "femmech.chain.frame",
    "Chain": "femmech.chain.model",
    "End": "femmech.chain.model",
    "chain": "femmech.chain.model",
    "follower_unit": "femmech.chain.model",
    "torsion_segment": "femmech.chain.model",
    "ChainModes": "femmech.chain.results",
    "chain_sweep": "femmech.chain.sweep",
    "compare_methods": "femmech.chain.sweep",
    "Parameter": "femmech.chain.synthesis",
    "SynthesisResult": "femmech.chain.synthesis",
    "resonance_margin": "femmech.chain.synthesis",
    "synthesise": "femmech.chain.synthesis",
    "assembled_modes": "femmech.chain.transfer",
    "count_below": "femmech.chain.transfer",
    "transfer_modes": "femmech.chain.transfer",
}
"""Public name → its module, imported on first use: a scene that only describes a chain
(``femmech check``) needs :mod:`.model`, not the optimiser of :mod:`.synthesis`."""

__all__ = ["guided_unit", "mount_chain", "Chain", "End", "chain", "follower_unit",
           "torsion_segment", "Parameter", "SynthesisResult", "resonance_margin", "synthesise",
           "cyclic_modes", "is_uniform", "pass_bands", "continuum_modes",
           "continuum_error_table", "ChainModes", "transfer_modes", "count_below",
           "assembled_modes", "chain_sweep", "compare_methods"]


__getattr__, __dir__ = lazy_names(__name__, _LAZY)
