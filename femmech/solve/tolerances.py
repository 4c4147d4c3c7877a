"""The tolerances of the eigen solvers, in one place, each with what it bounds.

Values that meant the same thing in several modules are one name here (those modules keep
their old names as aliases); values that look alike but bound different things have
different names that say which.

Stage 1, solve (linear algebra): imports nothing of femmech.
"""

from __future__ import annotations

SYMMETRY_RTOL = 1e-10
"""A stiffness C (frozen angle, chain unit, assembled chain) counts as symmetric, and its
pencil is solved by the symmetric routines on ``(C + Cᵀ)/2``, when
``max|C − Cᵀ| <= SYMMETRY_RTOL · max|C|``. Assembly round-off leaves ~1e-16; a truly
unsymmetric C (kinematic terms at Ω ≠ 0) differs by far more than 1e-10."""

REAL_RTOL = 1e-9
"""An eigenvalue λ (or root s) of an unsymmetric or damped pencil with
``|Im λ| <= REAL_RTOL · |λ|`` is real: QZ leaves imaginary parts of ~eps·cond on real ones."""

ZERO_OF_LARGEST_RTOL = 1e-12
"""A frozen-angle λ with ``|λ| <= ZERO_OF_LARGEST_RTOL · λ_top`` is zero (a rigid-body
mode), λ_top the largest ``|C_ii| / M_ii`` (an estimate of the largest eigenvalue): the
round-off of the dense solvers is ~eps of the largest eigenvalue."""

RIGID_TOL = 1e-12
"""An eigenvalue of ``K x = λ M x`` with ``|λ| <= RIGID_TOL · scale`` is a rigid-body
mode, scale a typical eigenvalue (:func:`femmech.solve.pencil.eigenvalue_scale`, the
median of diag K / diag M): computed rigid-body eigenvalues are ~1e-17 of it (either
sign), elastic modes at 1e-12 of it are ~1e-6 of the typical element frequency
(:data:`femmech.solve.eigen.RIGID_TOL`)."""

CHAIN_ZERO_RTOL = 1e-14
"""A root of the chain's transfer search with ``|λ|`` below this times the chain's trace
ratio of C and M over the node rotations is zero (rigid-body): the Wittrick–Williams count
has round-off of ~1e-16 of that scale near λ = 0
(:data:`femmech.chain.transfer.ZERO_RTOL`). A different scale from
:data:`ZERO_OF_LARGEST_RTOL` (a mean, not the largest eigenvalue), hence the smaller value."""

INFINITE_MU_RTOL = 1e-12
"""In the shift-inverted pencil ``M x = μ (K − σM) x``, μ below this times the largest μ
belongs to a massless direction (infinite λ) and is dropped."""

DENSE_BELOW = 400
"""A symmetric pencil with fewer coordinates than this is solved by dense LAPACK
(:func:`femmech.solve.eigen.solve_symmetric`, ``assembled_modes(solver="auto")`` of a
chain), a larger one by sparse shift-invert Lanczos; measurements in
benchmarks/README.md."""

STURM_CHECK_MAX = 2000
"""Not a dense cut-over: ``transfer_modes(verify=None)`` checks the chain's
Wittrick–Williams count against the assembled model's sparse Sturm count up to this many
coordinates (:data:`femmech.chain.transfer.STURM_CHECK_MAX`)."""
