"""Stage 1, linear algebra of symmetric eigenproblems ``K x = λ M x``; knows nothing of FE.

Modules, one job each:

* :mod:`.threads`: BLAS/OpenMP threads per phase (solve loops, factorisations);
* :mod:`.factor`: the interface of a sparse direct factorisation (:class:`~.factor.Factor`);
* :mod:`.superlu`, :mod:`.cholmod`, :mod:`.pardiso`: its backends (SuperLU, CHOLMOD, MKL
  PARDISO);
* :mod:`.direct`: backend selection and :func:`~.direct.factorize`;
* :mod:`.pencil`: the pencil's eigenvalue scale, default shift, DOFs with mass and the
  factorisation of ``K - σ M``;
* :mod:`.residuals`: mass normalisation of modes, residuals and their limits;
* :mod:`.sturm`: Sturm-sequence (inertia) counts and cluster completion;
* :mod:`.dense`: the one dense pencil solver (symmetric, unsymmetric, damped; one pencil
  or a stack of angles);
* :mod:`.tolerances`: the tolerances every solve path shares (symmetry, zero, real, cut-over);
* :mod:`.arpack`: shift-invert ARPACK with deflation (bands, fallback);
* :mod:`.lanczos`: femmech's shift-invert block Lanczos for the lowest modes;
* :mod:`.eigen`: the driver :func:`~femmech.solve.eigen.solve_symmetric` and its result
  :class:`~femmech.solve.eigen.EigenResult`;
* :mod:`.lobpcg`: AMG-preconditioned LOBPCG for models too large to factorise.

Imports only :mod:`femmech.errors` and modules of this package; within it the imports go
one way, down this order: lobpcg, eigen, lanczos, arpack/dense/sturm, residuals, pencil,
direct, the backends, factor, threads.
"""
