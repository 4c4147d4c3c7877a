"""Vectorised numerical evaluation of symbolic mechanism equations.

Symbolic expressions from :mod:`femmech.mechanisms.lagrange` are turned into numpy
functions with ``sympy.lambdify`` (common-subexpression elimination on). Each applied
position function U^(k)(arg) is replaced by a placeholder symbol; at evaluation time the
argument ``arg`` is evaluated numerically, the user's numeric
:class:`~femmech.mechanisms.position.PositionFunction` is called once per distinct
argument, and its values U, U', U'', U''' are passed in. So cams, linkages and tabulated
functions plug into the same compiled equations, and the (slow) symbolic step is done
once per mechanism and cached.

Uses mechanisms.symbolic and .position.
"""

import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import sympy

from femmech.mechanisms.position import PositionFunction
from femmech.mechanisms.symbolic import position_function

__all__ = ["CompiledExpressions", "check_bindings", "compile_expressions"]


def _position_calls(exprs) -> list[tuple[str, sympy.Expr]]:
    """Distinct (name, argument) pairs of the position functions used in ``exprs``."""
    calls = set()
    for ex in exprs:
        for f in sympy.sympify(ex).atoms(sympy.Function):
            name = getattr(f, "position_name", None)
            if name is not None:
                calls.add((name, f.args[0]))
    return sorted(calls, key=lambda c: (c[0], sympy.srepr(c[1])))


@dataclass(frozen=True, eq=False)
class CompiledExpressions:
    """A list of expressions compiled for batch evaluation.

    Attributes
    ----------
    inputs : tuple of sympy.Symbol
        Symbols supplied as arrays at every call (drive angle, coordinates, …).
    parameters : tuple of sympy.Symbol
        Remaining free symbols, supplied as scalars (masses, stiffnesses, …).
    position_names : tuple of str
        Names of the position functions used.
    """

    inputs: tuple[sympy.Symbol, ...]
    parameters: tuple[sympy.Symbol, ...]
    position_names: tuple[str, ...]
    _calls: tuple[tuple[str, sympy.Expr], ...]
    _replaced: tuple[sympy.Expr, ...]
    _placeholders: tuple[sympy.Symbol, ...]
    _size: int

    @functools.cached_property
    def _arg_function(self):
        """The position functions' arguments as one numpy function (None without any)."""
        if not self._calls:
            return None
        return sympy.lambdify(self.inputs + self.parameters, [a for _, a in self._calls],
                              modules="numpy")

    @functools.cached_property
    def _function(self):
        """The expressions as one numpy function; lambdify runs at the first evaluation,
        so that checking a model's bindings (``femmech check``) does not pay for it."""
        return sympy.lambdify(self.inputs + self.parameters + self._placeholders,
                              list(self._replaced), modules="numpy", cse=True)

    def __call__(self, inputs: Sequence[np.ndarray], parameters: Sequence[float],
                 position_functions: Mapping[str, PositionFunction]) -> np.ndarray:
        """Evaluate all expressions; return an array of shape ``batch + (n_expr,)``.

        ``inputs`` are arrays broadcast against each other to the batch shape.
        """
        arrays = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in inputs))
        shape = arrays[0].shape if arrays else ()
        values = []
        if self._calls:
            args = self._arg_function(*arrays, *parameters)
            for (name, _), arg in zip(self._calls, args, strict=True):
                arg = np.broadcast_to(np.asarray(arg, dtype=float), shape)
                values.extend(position_functions[name].derivatives(arg))
        raw = self._function(*arrays, *parameters, *values)
        out = np.empty(shape + (self._size,))
        for i, r in enumerate(raw):
            out[..., i] = r
        return out


@functools.cache
def compile_expressions(exprs: tuple[sympy.Expr, ...],
                        inputs: tuple[sympy.Symbol, ...]) -> CompiledExpressions:
    """Compile ``exprs`` into one vectorised numpy function (cached per arguments).

    Parameters
    ----------
    exprs : tuple of sympy.Expr
        Expressions in ``inputs``, parameters and position functions.
    inputs : tuple of sympy.Symbol
        Symbols that vary per evaluation point (given as arrays).

    Returns
    -------
    CompiledExpressions
    """
    exprs = tuple(sympy.sympify(x) for x in exprs)
    calls = _position_calls(exprs)
    placeholders, replace = [], {}
    for i, (name, arg) in enumerate(calls):
        cls = position_function(name).family
        syms = sympy.symbols(f"_pf{i}_0:4", real=True)
        placeholders.extend(syms)
        replace.update({cls[k](arg): syms[k] for k in range(4)})
    replaced = [x.xreplace(replace) for x in exprs]
    for name, arg in calls:
        if any(getattr(f, "position_name", None) for f in arg.atoms(sympy.Function)):
            raise ValueError(f"position function {name!r} has an argument {arg} that contains "
                             "another position function; compose them numerically instead")
    free = set().union(*(x.free_symbols for x in replaced), *(a.free_symbols for _, a in calls))
    params = tuple(sorted(free - set(inputs) - set(placeholders), key=lambda s: s.name))
    leftover = [f for x in replaced for f in x.atoms(sympy.Function)
                if getattr(f, "position_name", None)]
    if leftover:
        raise ValueError(f"could not substitute position functions {leftover}")
    return CompiledExpressions(inputs, params, tuple(sorted({n for n, _ in calls})),
                               tuple(calls), tuple(replaced), tuple(placeholders), len(exprs))


def check_bindings(compiled: Sequence[CompiledExpressions], parameters: Mapping,
                   position_functions: Mapping, known: set[str]) -> tuple[
                       dict[str, float], dict[str, PositionFunction]]:
    """Check and normalise parameter values and position functions for ``compiled``.

    Parameters
    ----------
    compiled : sequence of CompiledExpressions
    parameters : mapping
        Symbol or symbol name → float value (SI units).
    position_functions : mapping
        Position-function name → object implementing ``PositionFunction``.
    known : set of str
        Names of all parameters of the mechanism; values for known parameters that the
        compiled expressions do not use (e.g. J0 with a kinematic drive) are accepted.

    Returns
    -------
    (dict, dict)
        Parameter values by name, position functions by name.

    Raises
    ------
    ValueError
        If a parameter or position function is missing or unknown.
    TypeError
        If a position function does not implement ``derivatives``.
    """
    values = {str(k): float(v) for k, v in parameters.items()}
    needed = {s.name for c in compiled for s in c.parameters}
    missing = sorted(needed - values.keys())
    unknown = sorted(values.keys() - needed - known)
    if missing:
        raise ValueError(f"missing values for parameters {missing}")
    if unknown:
        raise ValueError(f"unknown parameters {unknown}; the mechanism has "
                         f"{sorted(needed | known)}")
    funcs = dict(position_functions)
    names = {n for c in compiled for n in c.position_names}
    missing, unknown = sorted(names - funcs.keys()), sorted(funcs.keys() - names)
    if missing:
        raise ValueError(f"missing position functions {missing}")
    if unknown:
        raise ValueError(f"unknown position functions {unknown}; the mechanism uses "
                         f"{sorted(names)}")
    for n, f in funcs.items():
        if not isinstance(f, PositionFunction):
            raise TypeError(f"position function {n!r} ({type(f).__name__}) does not implement "
                            "derivatives(phi) and __call__(phi, order)")
    return values, funcs
