"""Stage 3: the superelement, a reduced model of a substructure with recovery of its field.

:class:`Superelement` holds the reduced matrices and the basis that expands reduced
coordinates to all DOFs of the FE model; it saves and loads itself through
:mod:`femmech.reduction.superelement_file`. :func:`interface_dofs` turns an interface
specification (groups, nodes, components) into the full-model DOFs that a reduction keeps.
The reductions that make superelements are in :mod:`femmech.reduction.component_modes`.

Imports :mod:`femmech.fe` and its own package; never the reduction algorithms.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from femmech.fe.dofs import DOF_PER_NODE, components, dof_label
from femmech.fe.model import FEModel, node_indices
from femmech.html import html_summary
from femmech.reduction import superelement_file

FORMAT_VERSION = superelement_file.FORMAT_VERSION
"""Format of superelement files (:mod:`femmech.reduction.superelement_file`)."""


@dataclass(frozen=True)
class Superelement:
    """Reduced model of a substructure, with recovery of the full field.

    Symbols: K stiffness, M mass (reduced, dense, symmetric). Reduced coordinates are
    the ``n_b`` physical interface DOFs (m, rad) followed by ``n_q`` modal amplitudes
    of the fixed-interface modes (kg^½ m, mass-normalised modes).

    Attributes
    ----------
    K, M : ndarray (n_r, n_r)
    method : str
        ``"guyan"`` or ``"craig-bampton"``.
    interface_dofs : ndarray (n_b,)
        Full-model DOF index of each interface coordinate (``6 * node + component``).
    interface_points : ndarray (n_b, 3)
        Coordinates (m) of the node of each interface DOF.
    modal_omega2 : ndarray (n_q,)
        Fixed-interface eigenvalues, rad²/s².
    Psi : ndarray (n_i, n_b)
        Constraint modes on the interior free DOFs.
    Phi : ndarray (n_i, n_q)
        Fixed-interface modes on the interior free DOFs.
    free_interface, free_interior : ndarray
        Positions of interface and interior DOFs among the model's free DOFs.
    T : scipy.sparse.csr_matrix (n_dof, n_free)
        The model's constraint transformation, for expansion to all DOFs.
    timings : dict[str, float]
        Seconds spent in ``factorisation``, ``constraint_modes``, ``fixed_interface_modes``
        and ``projection``.
    n_residual : int
        How many of the ``n_q`` modal coordinates are residual vectors (the last ones).
    interface_basis : ndarray (n_b, n_c) or None
        Reduced interface (:func:`femmech.reduction.interface_modes.reduce_interface`):
        the interface DOFs are ``u_b = V η_c`` with the first n_c reduced coordinates
        η_c (mode traces, attachment vectors, CC modes); ``Psi`` is then
        Ψ V (n_i, n_c). None for Guyan and plain Craig-Bampton (η_c = u_b).
    interface_factor : Factor or None
        Factorisation of the whole free ``K - σM`` kept by ``reduce_interface`` for
        :func:`~femmech.reduction.interface_modes.interface_error_estimates`.
    inertia_response : ndarray (n_i, n_b) or None
        ``K_ii⁻¹ (M_ii Ψ + M_ib)``, the interior's static response to the inertia forces
        of unit interface accelerations: solved for the residual vectors and kept (up to
        :data:`~femmech.reduction.component_modes.KEEP_RESPONSE_BYTES`) so that
        :func:`~femmech.reduction.estimate.coupled_error_forms` does not solve it again.
        Not saved to files.
    """

    K: np.ndarray
    M: np.ndarray
    method: str
    interface_dofs: np.ndarray
    interface_points: np.ndarray
    modal_omega2: np.ndarray
    Psi: np.ndarray
    Phi: np.ndarray
    free_interface: np.ndarray
    free_interior: np.ndarray
    T: sp.csr_matrix
    timings: dict = field(default_factory=dict)
    n_residual: int = 0
    interior_factor: object = field(default=None, compare=False, repr=False)
    interface_basis: np.ndarray | None = field(default=None, compare=False, repr=False)
    interface_factor: object = field(default=None, compare=False, repr=False)
    inertia_response: np.ndarray | None = field(default=None, compare=False, repr=False)

    def __repr__(self) -> str:
        modal = f", {self.n_modal} modal" if self.n_modal else ""
        residual = f" ({self.n_residual} residual vectors)" if self.n_residual else ""
        cc = "" if self.interface_basis is None else f" in {self.n_boundary} interface modes"
        return (f"Superelement({self.method}: {self.n_reduced} coordinates ="
                f" {self.n_interface} interface DOFs{cc}{modal}{residual}; full model"
                f" {self.n_dof} DOFs)")

    def _repr_html_(self) -> str:
        f = self.modal_freq_hz
        facts = [("method", self.method),
                 ("interface DOFs", self.n_interface),
                 ("modal coordinates", f"{self.n_modal} ({self.n_residual} residual vectors)"),
                 ("full model DOFs", self.n_dof)]
        if f.size:
            facts.append(("fixed-interface modes / Hz", f"{f.min():.4g} … {f.max():.4g}"))
        return html_summary(f"Superelement: {self.n_reduced} coordinates", facts)

    @property
    def n_interface(self) -> int:
        """Number of physical interface DOFs n_b."""
        return len(self.interface_dofs)

    @property
    def n_boundary(self) -> int:
        """Number of reduced coordinates of the interface: n_c with a reduced interface
        (:attr:`interface_basis`), else n_b."""
        V = self.interface_basis
        return self.n_interface if V is None else V.shape[1]

    @property
    def n_modal(self) -> int:
        """Number of fixed-interface modes n_q."""
        return len(self.modal_omega2)

    @property
    def n_reduced(self) -> int:
        """Number of reduced coordinates n_b + n_q."""
        return self.K.shape[0]

    @property
    def n_dof(self) -> int:
        """Number of full-model DOFs."""
        return self.T.shape[0]

    @property
    def kinds(self) -> np.ndarray:
        """``"interface"`` (``"interface mode"`` with a reduced interface), ``"modal"`` or
        ``"residual"`` per reduced coordinate, (n_r,)."""
        n_fixed = self.n_modal - self.n_residual
        kind = "interface" if self.interface_basis is None else "interface mode"
        return np.array([kind] * self.n_boundary + ["modal"] * n_fixed
                        + ["residual"] * self.n_residual)

    @property
    def modal_freq_hz(self) -> np.ndarray:
        """Fixed-interface natural frequencies, Hz."""
        return np.sqrt(np.clip(self.modal_omega2, 0.0, None)) / (2 * np.pi)

    def interface_labels(self) -> list[str]:
        """Readable labels such as ``"node 12 uz"`` for the interface coordinates."""
        return [dof_label(int(d)) for d in self.interface_dofs]

    def expand_free(self, q: np.ndarray) -> np.ndarray:
        """Free-DOF vector(s) (n_free, ...) from reduced coordinates q (n_r, ...)."""
        q = np.asarray(q)
        q = q.astype(np.result_type(q.dtype, float), copy=False)  # real or complex modes
        if q.shape[0] != self.n_reduced:
            raise ValueError(f"reduced vector has {q.shape[0]} rows, the superelement"
                             f" has {self.n_reduced} coordinates")
        qb, qm = q[:self.n_boundary], q[self.n_boundary:]
        u = np.zeros((self.T.shape[1],) + q.shape[1:], dtype=q.dtype)
        V = self.interface_basis
        u[self.free_interface] = qb if V is None else np.tensordot(V, qb, 1)
        u[self.free_interior] = np.tensordot(self.Psi, qb, 1) + np.tensordot(self.Phi, qm, 1)
        return u

    def recover(self, q: np.ndarray) -> np.ndarray:
        """Full-model DOF vector(s) (n_dof, ...) from reduced coordinates q (n_r, ...).

        Works for a static solution, a mode shape or a time history (columns).
        """
        u = self.expand_free(q)
        return (self.T @ u.reshape(u.shape[0], -1)).reshape((self.n_dof,) + u.shape[1:])

    def save(self, path) -> Path:
        """Write to one ``.npz`` file (atomically); read back with :meth:`load`.

        The format and its checks are described in :mod:`femmech.reduction.superelement_file`.
        """
        return superelement_file.write(self, path)

    @classmethod
    def load(cls, path) -> Superelement:
        """Read a superelement written by :meth:`save`, validating every field first.

        Raises
        ------
        FileNotFoundError
            If there is no file ``path``.
        FileFormatError
            (a ValueError) with one line naming the file and the field, if the file is
            truncated, damaged, foreign, inconsistent or of an unknown format version.
        """
        return cls(**superelement_file.read(path))


def interface_dofs(model: FEModel, interface) -> np.ndarray:
    """Full-model DOF indices of an interface specification.

    Parameters
    ----------
    model : FEModel
    interface : str, int, or sequence of (str | int | (nodes, components))
        Group names or node indices (all six DOFs of each node), or pairs of a group/
        node(s) and components (``("guide", ["uy", "uz"])``). "All DOFs" (a bare group or
        node, or the components ``"all"``) means the active ones: a node that only solid
        elements use has translations only (its rotations are
        :attr:`~femmech.fe.model.FEModel.inactive`), so its three translations are taken.
        A group leaves out the translations of the centre nodes of quad8 skins on solid
        faces (:attr:`~femmech.fe.model.FEModel.tied`): they follow the cells' other
        nodes, which a cell set holds too.

    Returns
    -------
    ndarray of int, sorted, unique.

    Raises
    ------
    ValueError
        Naming the DOF if it is supported or the slave of a rigid link (not a free DOF),
        or a rotation of a solid-only node named explicitly (with what to write instead).
    """
    items = [interface] if isinstance(interface, (str, int, np.integer)) else list(interface)
    if not items:
        raise ValueError("the interface is empty: give node sets, nodes or (nodes, dofs)")
    dofs = []
    for item in items:
        ref, spec = item if isinstance(item, tuple) and len(item) == 2 else (item, "all")
        nodes = node_indices(model.mesh, ref, "interface")
        found = (DOF_PER_NODE * nodes[:, None] + components(spec)).ravel()
        tied = np.isin(found, model.tied)
        if isinstance(ref, str):
            found = found[~tied]
        elif tied.any():
            raise ValueError(f"interface DOF {dof_label(int(found[tied][0]))} belongs to the"
                             " centre node of a quad8 skin on a solid face, which follows the"
                             " cell's eight nodes; give those nodes or the skin's group")
        inactive = np.isin(found, model.inactive)
        if isinstance(spec, str) and spec == "all":
            found = found[~inactive]
        elif inactive.any():
            raise ValueError(_inactive_message(ref, int(found[inactive][0])))
        dofs.append(found)
    dofs = np.unique(np.concatenate(dofs))
    position = np.searchsorted(model.free, dofs)
    position = np.minimum(position, model.free.size - 1)
    bad = dofs[model.free[position] != dofs]
    if bad.size:
        raise ValueError(f"interface DOF {dof_label(int(bad[0]))} is not a free DOF (it is"
                         " supported or the slave of a rigid link); use the master node or"
                         " drop the support")
    return dofs


def _inactive_message(ref, dof: int) -> str:
    """Why an interface may not name the rotation ``dof`` of a solid-only node."""
    return (f"interface {ref!r}: {dof_label(dof)} is a rotation of a node that only solid"
            " elements use; solids have no rotational stiffness, so the model has no such"
            f" DOF. Give the translations, ({ref!r}, 'translations') (in a scene: dofs ="
            " \"translations\", or leave dofs out), or join the node to a beam or a rigid"
            " link to carry rotations")
