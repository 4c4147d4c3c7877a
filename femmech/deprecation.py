"""Names resolved on first use: public names that moved keep working, with a
DeprecationWarning, and a package's public names load their modules when first used.

An old place is either a module that lost names (it ends with a module-level
``__getattr__``, PEP 562) or a module file kept only for its old path (nothing in it but
that ``__getattr__``). Both call :func:`moved` with a table ``{old name: new dotted
path}``; the new place is imported by its name only when an old name is used, so an old
place adds no import edge and cannot close an import circle. docs/architecture.md
("Moved names") lists every moved name; tests/test_deprecated_names.py checks each.

:func:`lazy_names` gives a package ``__init__`` its ``__getattr__`` and ``__dir__`` from a
table ``{public name: module}`` (and its table of moved names), so that importing the
package (``femmech check`` does) imports none of the modules behind those names until
one is used.

Imports nothing of femmech.
"""

from __future__ import annotations

import importlib
import os
import sys
import warnings
from collections.abc import Callable, Mapping

_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def _caller_level() -> int:
    """``stacklevel`` for a ``warnings.warn`` in the caller of this function that names the
    first frame outside femmech and the import system (the user's line)."""
    frame, level = sys._getframe(2), 2
    while frame is not None and (frame.f_code.co_filename.startswith(_PACKAGE)
                                 or frame.f_code.co_filename.startswith("<frozen importlib")):
        frame, level = frame.f_back, level + 1
    return level if frame is not None else 2


def moved(old: str, name: str, names: dict[str, str], removed: dict[str, str] | None = None):
    """The object an old name ``old.name`` stands for, with a DeprecationWarning.

    Parameters
    ----------
    old : str
        The old module, e.g. ``"femmech.io"`` (the caller's ``__name__``).
    name : str
        The attribute asked for.
    names : dict
        Old name → its new dotted path, e.g. ``{"from_meshio":
        "femmech.fe.mesh_io.from_meshio"}`` (the last part is the name at the new place).
    removed : dict, optional
        Old name → why it is gone and what replaces it (an AttributeError says so).

    Raises
    ------
    AttributeError
        For a name that is neither moved nor removed (as a module without it would).
    """
    new = names.get(name)
    if new is not None:
        module, _, attr = new.rpartition(".")
        warnings.warn(f"{old}.{name} moved to {new}", DeprecationWarning,
                      stacklevel=_caller_level())
        return getattr(importlib.import_module(module), attr)
    if removed and name in removed:
        raise AttributeError(f"{old}.{name} was removed: {removed[name]}")
    raise AttributeError(f"module {old!r} has no attribute {name!r}")


def alias_module(old: str, new: str) -> None:
    """Make the old module path ``old`` the module ``new`` itself, with a DeprecationWarning.

    For an old path whose name is still an attribute of its package (``femmech.generators``
    is :mod:`femmech.fe.generators`): importing the old path must not replace that
    attribute by a different module object. Call it from the old path's module file.
    """
    warnings.warn(f"{old} moved to {new}", DeprecationWarning, stacklevel=_caller_level())
    sys.modules[old] = importlib.import_module(new)


def lazy_names(package: str, names: Mapping[str, str],
               moved_names: Mapping[str, str] | None = None,
               fallback: Callable[[str], object] | None = None):
    """``(__getattr__, __dir__)`` for the package ``package`` (its ``__name__``).

    Parameters
    ----------
    package : str
        The package the functions are for.
    names : mapping
        Public name → the module it is imported from on first use; a name the module
        lacks is its submodule of that name (``femmech.fe`` → ``femmech.fe.generators``).
    moved_names : mapping, optional
        Old name → its new dotted path: a DeprecationWarning, then the object.
    fallback : callable, optional
        Called with any other name (e.g. old top-level modules); it raises
        AttributeError for what it does not know.
    """

    def get_attribute(name: str):
        if name in names:
            module = importlib.import_module(names[name])
            try:
                value = getattr(module, name)
            except AttributeError:  # a submodule not imported by its package
                value = importlib.import_module(f"{names[name]}.{name}")
            setattr(sys.modules[package], name, value)  # later look-ups skip this function
            return value
        if fallback is not None:
            return fallback(name)
        if moved_names:
            return moved(package, name, dict(moved_names))
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def list_names() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(names))

    get_attribute.__doc__ = (f"A public name of {package} from its module, imported on"
                             " first use (PEP 562); moved names warn and lead to their new"
                             " places.")
    return get_attribute, list_names
