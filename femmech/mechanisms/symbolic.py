"""Symbolic description of a lumped mechanism (bodies, springs, dampers, loads).

A mechanism is described by its generalized coordinates q = (q_1, …, q_N) (sympy
symbols), the subset of them that are drive ("program") coordinates, and elements whose
geometry is given by sympy expressions in q:

* :class:`PointMass` m at position r(q) and :class:`RotaryInertia` J at angle α(q): the
  kinetic energy 2T = Σ m |ṙ|² + Σ J α̇² (seed 5.2.1 eq. 1);
* :class:`Spring` c with deflection s(q) and :class:`Potential` V(q): the potential energy
  (5.2.1 eq. 7);
* :class:`Damper` b with deflection s(q) and :class:`Load` F acting along a displacement
  s(q): the non-potential forces Q*_j of eqs. 10–12.

Position functions of cams and linkages enter as opaque sympy functions made by
:func:`position_function`: ``U = position_function("U")`` gives a function whose
derivatives are the opaque functions U', U'', U'''. Their numeric values are supplied
when the equations are evaluated (see :mod:`femmech.mechanisms.evaluate`).

Imports nothing of femmech.
"""

import functools
from dataclasses import dataclass, field

import sympy

__all__ = [
    "Damper",
    "Load",
    "Mechanism",
    "PointMass",
    "Potential",
    "RotaryInertia",
    "Spring",
    "position_function",
    "velocity_symbol",
]

MAX_ORDER = 3


@functools.cache
def position_function(name: str) -> type:
    """Return the opaque sympy function for the position function called ``name``.

    Parameters
    ----------
    name : str
        Name under which the numeric position function is supplied at evaluation time
        (a valid Python identifier, e.g. ``"U1"``).

    Returns
    -------
    type
        A ``sympy.Function`` subclass U with ``diff`` chain U → U' → U'' → U'''. The
        classes carry ``position_name``, ``order`` and ``family`` (all four classes)
        attributes. Repeated calls with the
        same name return the same class.

    Raises
    ------
    ValueError
        If ``name`` is not an identifier, or (when differentiating) if an expression
        needs the fourth derivative U'''', which position functions do not provide.

    Examples
    --------
    >>> import sympy
    >>> U = position_function("U")
    >>> q = sympy.Symbol("q")
    >>> sympy.diff(U(2 * q), q, 2)
    4*U''(2*q)
    """
    if not name.isidentifier():
        raise ValueError(f"position function name must be an identifier, got {name!r}")
    classes: list[type] = []

    def fdiff(self, argindex=1):
        if self.order == MAX_ORDER:
            raise ValueError(f"the expression needs the 4th derivative of position function "
                             f"{name!r}; only U, U', U'', U''' are available")
        return classes[self.order + 1](self.args[0])

    for order in range(MAX_ORDER + 1):
        attrs = {"nargs": 1, "fdiff": fdiff, "position_name": name, "order": order}
        classes.append(type(name + "'" * order, (sympy.Function,), attrs))
    for cls in classes:
        cls.family = tuple(classes)
    return classes[0]


def velocity_symbol(q: sympy.Symbol) -> sympy.Symbol:
    """Return the symbol used for the velocity q̇ of coordinate ``q`` (named ``<q>_dot``).

    Use it in :class:`Load` magnitudes that depend on velocities.
    """
    return sympy.Symbol(f"{q.name}_dot", real=True)


def _expr(value) -> sympy.Expr:
    return sympy.sympify(value)


@dataclass(frozen=True)
class PointMass:
    """Point mass (or body translation) m, kg, at position r(q) = (x, y[, z]), m."""

    m: sympy.Expr
    position: tuple[sympy.Expr, ...]

    def __post_init__(self):
        object.__setattr__(self, "m", _expr(self.m))
        object.__setattr__(self, "position", tuple(_expr(x) for x in self.position))


@dataclass(frozen=True)
class RotaryInertia:
    """Moment of inertia J, kg·m², of a body turning at angle α(q), rad (planar)."""

    J: sympy.Expr
    angle: sympy.Expr

    def __post_init__(self):
        object.__setattr__(self, "J", _expr(self.J))
        object.__setattr__(self, "angle", _expr(self.angle))


@dataclass(frozen=True)
class Spring:
    """Linear spring c (N/m or N·m/rad) with deflection s(q); V = c s²/2."""

    c: sympy.Expr
    deflection: sympy.Expr

    def __post_init__(self):
        object.__setattr__(self, "c", _expr(self.c))
        object.__setattr__(self, "deflection", _expr(self.deflection))


@dataclass(frozen=True)
class Damper:
    """Viscous damper b (N·s/m or N·m·s/rad) on deflection s(q); Q*_j = −b ṡ ∂s/∂q_j."""

    b: sympy.Expr
    deflection: sympy.Expr

    def __post_init__(self):
        object.__setattr__(self, "b", _expr(self.b))
        object.__setattr__(self, "deflection", _expr(self.deflection))


@dataclass(frozen=True)
class Load:
    """Applied or process force F (N or N·m) doing the virtual work F δs(q).

    ``magnitude`` may depend on q and on velocities (:func:`velocity_symbol`); a force
    opposing the motion of the output x is ``Load(-F, x)``. Q*_j = F ∂s/∂q_j (eq. 11).
    """

    magnitude: sympy.Expr
    displacement: sympy.Expr

    def __post_init__(self):
        object.__setattr__(self, "magnitude", _expr(self.magnitude))
        object.__setattr__(self, "displacement", _expr(self.displacement))


@dataclass(frozen=True)
class Potential:
    """Additional potential energy V(q), J (e.g. gravity ``m*g*y``)."""

    energy: sympy.Expr

    def __post_init__(self):
        object.__setattr__(self, "energy", _expr(self.energy))


Element = PointMass | RotaryInertia | Spring | Damper | Load | Potential


@dataclass(frozen=True)
class Mechanism:
    """Symbolic lumped mechanism: coordinates, drive coordinates, elements, constraints.

    Parameters
    ----------
    coordinates : tuple of sympy.Symbol
        All generalized coordinates q_1 … q_N (plus redundant ones for the mixed form),
        in the order of the matrices.
    elements : tuple of Element
        Masses, inertias, springs, dampers, loads and potentials.
    drives : tuple of sympy.Symbol
        The drive (program) coordinates, a subset of ``coordinates`` whose motion is
        prescribed in the rheolinear form (seed 5.2.2); the others are the vibration
        coordinates.
    constraints : tuple of sympy.Expr
        Holonomic, scleronomic constraints f_i(q) = 0 linking redundant coordinates
        (seed 5.2.1 eq. 15), used by the mixed-type form.
    name : str
        Label for messages and plots.
    labels : tuple of (str, str)
        (coordinate name, what it is physically) pairs, e.g. ``(("q", "follower
        deformation"),)``, for readable table headers and plot legends
        (:func:`femmech.mechanisms.catalogue.describe`); the built-in factories give them
        from :data:`~femmech.mechanisms.catalogue.CATALOGUE`. Not part of equality (two
        mechanisms that differ only in labels share their cached equations).

    Raises
    ------
    ValueError
        For repeated coordinates, drives that are not coordinates, or unknown element types.
    """

    coordinates: tuple[sympy.Symbol, ...]
    elements: tuple[Element, ...]
    drives: tuple[sympy.Symbol, ...] = ()
    constraints: tuple[sympy.Expr, ...] = ()
    name: str = ""
    labels: tuple[tuple[str, str], ...] = field(default=(), compare=False)

    def __post_init__(self):
        for attr in ("coordinates", "elements", "drives", "labels"):
            object.__setattr__(self, attr, tuple(getattr(self, attr)))
        object.__setattr__(self, "constraints", tuple(_expr(f) for f in self.constraints))
        if len(set(self.coordinates)) != len(self.coordinates):
            raise ValueError(f"mechanism {self.name!r}: coordinates are repeated")
        for q in self.coordinates:
            if not isinstance(q, sympy.Symbol):
                raise TypeError(f"coordinate {q!r} is not a sympy Symbol")
        for d in self.drives:
            if d not in self.coordinates:
                raise ValueError(f"drive {d} is not one of the coordinates {self.coordinates}")
        names = {q.name for q in self.coordinates}
        for item in self.labels:
            if not (isinstance(item, tuple) and len(item) == 2 and item[0] in names
                    and isinstance(item[1], str)):
                raise ValueError(f"mechanism {self.name!r}: labels must be (coordinate name,"
                                 f" text) pairs of its coordinates {sorted(names)}, got"
                                 f" {item!r}")
        for i, el in enumerate(self.elements):
            if not isinstance(el, PointMass | RotaryInertia | Spring | Damper | Load | Potential):
                raise TypeError(f"element {i} has unsupported type {type(el).__name__}")

    @property
    def parameters(self) -> frozenset[sympy.Symbol]:
        """Free symbols of elements and constraints other than coordinates and velocities.

        These are the parameters (masses, stiffnesses, lengths, forces, …).
        """
        exprs = [x for el in self.elements for x in vars(el).values()]
        free = set().union(*(sympy.sympify(x).free_symbols if not isinstance(x, tuple) else
                             set().union(*(y.free_symbols for y in x)) for x in exprs),
                           *(f.free_symbols for f in self.constraints))
        coords = set(self.coordinates) | {velocity_symbol(q) for q in self.coordinates}
        return frozenset(free - coords)

    @property
    def vibration_coordinates(self) -> tuple[sympy.Symbol, ...]:
        """The coordinates that are not drives, in their original order."""
        return tuple(q for q in self.coordinates if q not in self.drives)
