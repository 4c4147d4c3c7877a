"""Old path of :mod:`femmech.fe.sections` (the module itself, with a DeprecationWarning
on import; ``femmech.sections`` as an attribute of femmech is current).

Kept for scripts written against the previous layout (docs/architecture.md, "Moved
names"); nothing inside femmech imports it.
"""

from femmech.deprecation import alias_module

alias_module(__name__, "femmech.fe.sections")
