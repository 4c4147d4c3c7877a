"""The mechanism types scenes can name (``model = "..."``), registered next to their factory.

A factory module registers each mechanism type it offers (:func:`register`, right after
the factory): its scene name, the factory, and which :data:`~femmech.mechanisms.catalogue.
CATALOGUE` entry describes it for given factory options. Everything else a scene needs is
read from that entry: the parameters with their SI units (fixed names, and the *roles*
that a factory option renames), the coordinates and the derived output quantities.
Adding a mechanism type to scenes therefore is its catalogue entry plus one registration
(docs/architecture.md, "Where to add things").

Stage 2 (mechanisms, independent of fe): uses only mechanisms.catalogue.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass

from femmech.mechanisms.catalogue import CATALOGUE, Coordinate, Entry


def _no_options(name: str) -> Callable[[dict], str]:
    return lambda options: f"{name}()"


@dataclass(frozen=True)
class MechanismType:
    """One mechanism type of scenes.

    Attributes
    ----------
    name : str
        Scene spelling (``model = name``).
    factory : callable
        ``factory(**options) -> Mechanism``; scene ``options`` are its keyword arguments.
    call : callable, optional
        ``call(options) -> str``: the :data:`~femmech.mechanisms.catalogue.CATALOGUE` key
        of the variant these options build (default ``"<name>()"``).
    variants : tuple of str
        Every catalogue key the options can select (default: ``("<name>()",)``); their
        parameters are the type's parameters with fixed names.
    """

    name: str
    factory: Callable
    call: Callable[[dict], str] | None = None
    variants: tuple[str, ...] = ()

    def __post_init__(self):
        if not callable(self.factory):
            raise TypeError(f"mechanism type {self.name!r}: factory must be callable")
        for key in self.variants or (f"{self.name}()",):
            if key not in CATALOGUE:
                raise ValueError(f"mechanism type {self.name!r}: no catalogue entry {key!r}")

    def entry(self, options: dict) -> Entry | None:
        """The catalogue entry of the variant ``options`` build (None if there is none)."""
        call = (self.call or _no_options(self.name))(options)
        return CATALOGUE.get(call)

    def parameter_units(self, options: dict) -> dict[str, str]:
        """Parameter name → SI unit for these factory options: the fixed names of every
        variant, and each role (a parameter a factory option renames) under the name the
        option gives it (its default when unset; none when that is None)."""
        units, roles = {}, {}
        for key in self.variants or (f"{self.name}()",):
            for p in CATALOGUE[key].parameters:
                if p.option:
                    roles[p.option] = p.unit
                else:
                    units[p.name] = p.unit
        defaults = inspect.signature(self.factory).parameters
        for role, unit in roles.items():
            name = options.get(role, defaults[role].default)
            if isinstance(name, str):
                units[name] = unit
        return units

    def quantities(self, options: dict) -> tuple[Coordinate, ...]:
        """The coordinates and derived output quantities of the variant ``options`` build."""
        entry = self.entry(options)
        return entry.coordinates + entry.quantities if entry is not None else ()


MECHANISM_TYPES: dict[str, MechanismType] = {}
"""Registered mechanism types by scene name, in registration order."""


def register(kind: MechanismType) -> MechanismType:
    """Make ``kind`` known to scenes; a name registers once."""
    if kind.name in MECHANISM_TYPES:
        raise ValueError(f"mechanism type {kind.name!r} is already registered"
                         f" ({MECHANISM_TYPES[kind.name].factory.__qualname__})")
    MECHANISM_TYPES[kind.name] = kind
    return kind
