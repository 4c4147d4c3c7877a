"""Stage 1, linear algebra of symmetric eigenproblems ``K x = λ M x``; knows nothing of FE.

Modules: :mod:`.threads` (BLAS/OpenMP threads per phase), :mod:`.direct` (sparse
direct factorisations behind one interface: SuperLU, CHOLMOD, PARDISO), :mod:`.eigen`
(the driver :func:`~femmech.solve.eigen.solve_symmetric`), :mod:`.lobpcg` (AMG-
preconditioned LOBPCG for models too large to factorise).

Imports only :mod:`femmech.errors`.
"""
