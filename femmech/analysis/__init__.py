"""Analyses: modes, sweeps, stability, response.

One job per module:

* :mod:`.modes`: free vibration modes of an FE model or a superelement.
* :mod:`.mode_types`: a mode's kind (bending, torsion, axial, rigid body) from energy
  fractions.
* :mod:`.sweep`: quasi-eigenfrequencies and quasi-modes of a coupled machine over the
  drive angle.
* :mod:`.tracking`: mode tracking shared by the angle and chain sweeps (MAC, clusters,
  branch assignment).
* :mod:`.reference`: full (unreduced) coupled reference solves, reduced versus full.
* :mod:`.magnus`: monodromy matrices by a fourth-order Magnus integrator with step
  doubling.
* :mod:`.floquet`: Floquet multipliers and exponents of periodic systems and coupled
  machines.
* :mod:`.stability`: stability charts over drive speed (and a parameter), speed studies.
* :mod:`.response`: forced response in time (generalised-α), periodic steady states.
* :mod:`.forces`: attachment, drive, support and section forces from time histories.
* :mod:`.nonlinear`: time integration of the nonlinear mechanism equations (seed 5.2.1).
* :mod:`.drive_events`: prescribed-drive load cases: static rest, run-up, trip at a
  drive-force limit, braking (a crane's load-moment limiter, a press's overload clutch).
* :mod:`.studies`: design studies as independent jobs on an executor (processes, Dask).
* :mod:`.discretisation`: the discretisation error of a model's frequencies by one
  refinement; :mod:`.participation`: mass properties and modal participation;
  :mod:`.shell_checks`: spurious drilling modes of shell models.

Uses coupling, reduction, fe, mechanisms, solve and errors; nothing
here writes files (that is :mod:`femmech.output`).
"""
