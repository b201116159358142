"""Compact tables of where each compiled instruction came from.

A loaded program keeps, for each instruction, its STL location (run-time
errors, ``plcrt dump``, the debugger) and the line of the generated module
where its code starts (the location of a fault from a traceback).  A
hundred thousand :class:`~plcrt.errors.SourceLoc` objects and a dict keyed
by line number cost about 20 MiB; these tables keep the same facts in a few
arrays of machine integers (about 20 bytes per instruction) and build the
``SourceLoc`` when one is asked for.  They behave as the list and the dict
they replace: :class:`LocTable` is a sequence (instruction id -> location),
:class:`LineLocs` a mapping (generated line -> location).
"""

from __future__ import annotations

from array import array
from bisect import bisect_right
from collections.abc import Iterator, Mapping, Sequence
from typing import overload

from ..errors import SourceLoc


class LocTable(Sequence[SourceLoc]):
    """Instruction id -> :class:`SourceLoc`, appended in id order.

    Each entry is four unsigned integers: the file (an index into the few
    file names), line, column and the (block, network) pair (an index into
    the pairs seen).  ``table[i]`` returns a location equal to the one
    appended."""

    __slots__ = ("_files", "_file_index", "_places", "_place_index", "_data")

    def __init__(self) -> None:
        self._files: list[str] = []
        self._file_index: dict[str, int] = {}
        self._places: list[tuple[str | None, int | None]] = []
        self._place_index: dict[tuple[str | None, int | None], int] = {}
        #: file, line, column, place of each instruction, one after the other
        self._data = array("I")

    def append(self, loc: SourceLoc) -> None:
        """Add the location of the next instruction id."""
        f = self._file_index.get(loc.file)
        if f is None:
            f = self._file_index[loc.file] = len(self._files)
            self._files.append(loc.file)
        key = (loc.block, loc.network)
        p = self._place_index.get(key)
        if p is None:
            p = self._place_index[key] = len(self._places)
            self._places.append(key)
        self._data.extend((f, loc.line, loc.column, p))

    def __len__(self) -> int:
        return len(self._data) >> 2

    @overload
    def __getitem__(self, index: int) -> SourceLoc: ...

    @overload
    def __getitem__(self, index: slice) -> list[SourceLoc]: ...

    def __getitem__(self, index: int | slice) -> SourceLoc | list[SourceLoc]:
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        n = len(self)
        if not -n <= index < n:
            raise IndexError("instruction id out of range")
        k = (index % n) * 4
        f, line, column, p = self._data[k:k + 4]
        block, network = self._places[p]
        return SourceLoc(self._files[f], line, column, block, network)

    def __iter__(self) -> Iterator[SourceLoc]:
        return (self[i] for i in range(len(self)))


class LineLocs(Mapping[int, SourceLoc]):
    """Line of the generated module -> location of the instruction whose
    code starts there.

    ``starts[i]`` is the line where the code of instruction ``i`` starts
    (ids are given in the order the module is written, so the array never
    decreases) and ``indents[i]`` the indentation there; the keys are the
    distinct lines.  Instructions that leave their value pending (``LD a``
    before ``A b``) start on the same line as the next one: that line maps
    to the last of them, the one whose code is written there.  ``plcrt
    dump`` puts a marker comment for each instruction before its line."""

    __slots__ = ("_locs", "starts", "indents")

    def __init__(self, locs: Sequence[SourceLoc]) -> None:
        self._locs = locs
        self.starts = array("I")
        self.indents = array("B")

    def add(self, line: int, indent: int) -> None:
        """Record where the next instruction id's code starts."""
        if self.starts and line < self.starts[-1]:
            raise ValueError(f"instruction lines must not decrease ({line} after "
                             f"{self.starts[-1]})")
        self.starts.append(line)
        self.indents.append(indent)

    def _find(self, line: object) -> int:
        """The last instruction starting at ``line``, or -1."""
        if not isinstance(line, int):
            return -1
        i = bisect_right(self.starts, line) - 1
        return i if i >= 0 and self.starts[i] == line else -1

    def __getitem__(self, line: int) -> SourceLoc:
        i = self._find(line)
        if i < 0:
            raise KeyError(line)
        return self._locs[i]

    def __contains__(self, line: object) -> bool:
        return self._find(line) >= 0

    def __iter__(self) -> Iterator[int]:
        last = None
        for line in self.starts:
            if line != last:
                yield line
                last = line

    def __len__(self) -> int:
        return sum(1 for _ in self)


__all__ = ["LineLocs", "LocTable"]
