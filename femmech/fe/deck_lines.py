"""A deck read line by line with some of its lines hidden, for meshio's line readers.

meshio's Abaqus and Nastran readers read an open file by ``readline`` only and stop at
forms they do not know; femmech reads those parts itself (sets, spring and mass cards)
and hands meshio the rest through a :class:`HiddenLines` view of the open file.

Imports nothing else of femmech.
"""

from __future__ import annotations

import io


class HiddenLines(io.TextIOBase):
    """The lines of an open text file ``f`` without those :meth:`hides` marks.

    A subclass says per line whether it is hidden (it may keep state, e.g. inside a
    block); the end of the file (``""``) is always passed on."""

    def __init__(self, f):
        super().__init__()
        self.f = f

    def readable(self) -> bool:
        return True

    def read(self, size=-1):  # meshio tells a buffer by its read attribute
        raise io.UnsupportedOperation("read by lines")

    def hides(self, line: str) -> bool:
        """Whether ``line`` (with its line end) is hidden from the reader."""
        raise NotImplementedError

    def readline(self, size=-1) -> str:
        while True:
            line = self.f.readline()
            if not line or not self.hides(line):
                return line
