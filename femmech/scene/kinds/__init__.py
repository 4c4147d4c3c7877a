"""The analysis kinds of a scene, one module each: its spec (frozen dataclass), its table
reader, its runner and its report section, ending with ``KIND =``
:class:`~femmech.scene.kinds.common.AnalysisKind` (...). :mod:`femmech.scene.registry`
finds every module of this package (but :mod:`.common`, what they share) and orders them
by ``KIND.order``: :mod:`.modes`, :mod:`.sweep`, :mod:`.stability`, :mod:`.response`,
:mod:`.check`, :mod:`.drive_event`, :mod:`.chain_sweep`, :mod:`.campbell`,
:mod:`.synthesis`; read, run, ``femmech check`` and the docs all take the kinds from
there. Adding a kind is adding a module here (docs/architecture.md, "Where to add
things").

Nothing is imported here, so that reading a kind's module does not load the others.
"""
