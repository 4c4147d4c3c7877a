"""Old path of :mod:`femmech.fe.elements`: kept as a package for its old submodules
(:mod:`.beam`, :mod:`.shell`, :mod:`.solid`), whose names warn and lead to
femmech.fe.elements (docs/architecture.md, "Moved names"); nothing inside femmech
imports it.
"""
