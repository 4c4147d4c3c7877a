"""Exceptions and warnings of femmech.

Errors a user can fix (a scene, a mesh, a superelement or cache file, a command-line value,
a scene's own Python code) derive from :class:`InputError`; a computation that ran on valid
input but failed is a :class:`NumericalError`. Both derive from the builtin classes code
already catches (``ValueError``, ``RuntimeError``). The command line maps them to its
documented exit codes (:mod:`femmech.cli`).

:func:`did_you_mean` and :func:`name_list` word the messages for a name that does not
exist (a group of a mesh, a key), so that every stage lists the available names the same way.

Imports nothing of femmech; every module may import it.
"""

import difflib


class FemmechWarning(UserWarning):
    """A result was computed but deserves the user's attention (e.g. poor convergence)."""


class InputError(ValueError):
    """A user input is invalid; the one-line message names the file and the item (key,
    field, node, element, group or parameter) and what was expected."""


class SceneError(InputError):
    """A scene file is invalid; the one-line message names the file, the key and what was
    expected (``scene.toml: [parts.frame.sections.posts] section: expected one of ...``)."""


class FileFormatError(InputError):
    """A data file (superelement, cache entry, mesh) is damaged, foreign or inconsistent;
    the one-line message names the file and the field (``frame.npz: field 'K': not
    symmetric``). Such files are never executed (no pickle)."""


class UserCodeError(SceneError):
    """Python code named by a scene (``module =``) was refused (no opt-in, a path outside
    the allowed root) or failed when run (an exception or ``sys.exit``)."""


class NumericalError(RuntimeError):
    """A computation on valid input failed (no convergence, a singular matrix)."""


class ModelWarning(FemmechWarning):
    """A model input looks wrong (nearly coincident nodes, a free body by accident, a unit
    mix-up): the results are computed but are probably not those of the intended model.
    See :mod:`femmech.fe.checks`."""


class CacheWarning(FemmechWarning):
    """The reduction cache could not be read or written (read-only or full folder, a
    corrupt or foreign entry); the result was recomputed and is unaffected."""


class ConvergenceWarning(FemmechWarning):
    """A stepped or iterative result missed its tolerance; it is returned marked as
    unconverged (``converged=False``) with its error estimate, never as a plain number."""


MAX_LISTED_NAMES = 40
"""Most names :func:`name_list` spells out (a deck may hold thousands of sets)."""


def closest_name(word, names) -> str | None:
    """The name of ``names`` nearest to ``word``: one that differs only in case, else the
    closest by :func:`difflib.get_close_matches` (ratio >= 0.6, compared case-blind);
    None if none is near."""
    names = [str(n) for n in names]
    folded = {}
    for name in names:
        folded.setdefault(name.casefold(), name)
    word = str(word).casefold()
    if word in folded:
        return folded[word]
    close = difflib.get_close_matches(word, list(folded), n=1, cutoff=0.6)
    return folded[close[0]] if close else None


def did_you_mean(word, names) -> str:
    """``"; did you mean 'x'?"`` for the name of ``names`` nearest to ``word``, or ``""``."""
    near = closest_name(word, names)
    return f"; did you mean {near!r}?" if near is not None and near != word else ""


def name_list(names, limit: int = MAX_LISTED_NAMES) -> str:
    """``"['a', 'b']"``, sorted; past ``limit`` names ``"['a', ..., 'z'] and 12 more"``."""
    names = sorted(str(n) for n in names)
    if len(names) <= limit:
        return str(names)
    return f"{names[:limit]} and {len(names) - limit} more"
