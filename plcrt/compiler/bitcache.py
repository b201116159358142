"""Bits kept in locals across a run of bit-logic networks (Python backend).

What it is: :class:`BitCache`, the state the code generator keeps while it
emits one generated function of a block without jumps (a group of pieces,
:mod:`.codegen`).  Within a *region* -- consecutive instructions that only
read and write image bits and move the logic stack (:data:`REGION_INSNS`)
-- a bit of I, Q, M, V or S

* that the block reads again is read from memory once, into a local
  (``bM4_1 = (M[4] >> 1 & 1)``), and later contacts read the local;
* written by ``=`` is written to its local, and read from there by the
  contacts after it;
* written in the region is stored back into the image once, where the
  region ends: bits of one byte with one byte store (``Gen.wr_seq``).

A region ends before any other instruction (a box, a call, a jump, an
immediate contact or output, ENI, an edge, a return ...: everything that
may read or write memory some other way, run other code or leave the
function) and at the end of the function; the written bits are stored
there and every local is forgotten, so the next instruction sees the image
exactly as the straight code would leave it.  Nothing inside a region can
fault or run other code (interrupt routines run after the main program or
at ``ENI``: :mod:`plcrt.engine.interrupts`), so nobody sees the image
between two instructions of a region.  Instrumented builds (coverage
probes, breakpoints) and builds with the native backend do not use it:
a probe or a native segment between two networks sees the image as it is.

What it is not: not an optimiser of expressions (that is ``Gen``'s pending
value), not used for blocks with jumps or loops (a jump may land on any
piece: the image must be current at every piece's start).
"""

from __future__ import annotations

from collections import Counter
from typing import Any

from ..gen.emit import Gen
from ..gen.operands import Addr

#: instructions a region may hold: contacts, = and the logic stack.  They
#: read and write only direct image bits and stack levels.
REGION_INSNS = frozenset({"LD", "LDN", "A", "AN", "O", "ON", "=", "ALD", "OLD",
                          "LPS", "LRD", "LPP", "LDS", "NOT", "NOP"})
#: contacts: the instructions whose operand is counted (read again or not)
_CONTACTS = frozenset({"LD", "LDN", "A", "AN", "O", "ON"})
#: the areas whose bits may be kept: plain image bytes written only by the
#: program (SM is the scan's, T/C bits are the timers')
AREAS = frozenset({"I", "Q", "M", "V", "S"})


class BitCache:
    """The bits of the current region kept in locals (see the module doc)."""

    def __init__(self, reads: dict[int, int]) -> None:
        #: id of a contact -> how many contacts of its run read the same
        #: operand: a bit read once in its run is read from memory where it
        #: is used (a local would cost a store and a load more)
        self.reads = reads
        #: that count for the instruction being emitted (:meth:`at`)
        self.here = 0
        self.names: dict[tuple[str, int, int], str] = {}
        #: bits written in the region, in the order of their first write
        self.dirty: dict[tuple[str, int, int], Addr] = {}

    @classmethod
    def for_block(cls, pieces: list[Any]) -> "BitCache":
        """A cache for the pieces of one block: counts the operands of the
        contacts of each run (consecutive :data:`REGION_INSNS`; a run may
        still be cut where a function ends, which only makes a count high)."""
        reads: dict[int, int] = {}
        run: Counter[str] = Counter()
        members: list[tuple[int, str, bool]] = []     # (id, operand, is a contact)

        def close() -> None:
            later: set[str] = set()     # operands read after a point of the run
            # coils per byte as written ("Q0.1" -> "Q0"; a symbol counts
            # as a byte of its own): only a guess, it decides speed only
            coils = Counter(text.rpartition(".")[0] or text
                            for _k, text, contact in members if not contact)
            for key, text, contact in reversed(members):
                if contact:
                    reads[key] = run[text]
                    later.add(text)
                else:
                    # a coil: kept in a local if a contact after it reads
                    # the bit or another coil of the run writes its byte
                    shared = coils[text.rpartition(".")[0] or text] > 1
                    reads[key] = 1 if text in later or shared else 0
            run.clear()
            members.clear()
        for pc in pieces:
            for insn in pc.insns:
                if insn.mnemonic not in REGION_INSNS:
                    close()
                elif insn.operands and (insn.mnemonic in _CONTACTS or insn.mnemonic == "="):
                    text = insn.operands[0].text
                    contact = insn.mnemonic in _CONTACTS
                    if contact:
                        run[text] += 1
                    members.append((id(insn), text, contact))
        close()
        return cls(reads)

    def at(self, insn: Any) -> None:
        """The instruction of a run about to be emitted: for a contact the
        reads of its operand in the run, for ``=`` 1 to keep the bit in a
        local, 0 to write the image at once."""
        self.here = self.reads.get(id(insn), 0)

    @staticmethod
    def _key(op: Addr) -> tuple[str, int, int]:
        return (op.area, op.offset, op.bit)

    @staticmethod
    def _name(op: Addr) -> str:
        return f"b{op.area}{op.offset}_{op.bit}"

    def read(self, g: Gen, op: Addr, plain: str) -> str:
        """The expression reading bit ``op`` (``plain`` reads memory)."""
        if op.area not in AREAS:
            return plain
        key = self._key(op)
        name = self.names.get(key)
        if name is not None:
            return name
        if g.indent != 1 or self.here < 2:
            return plain
        name = self._name(op)
        # perf: the load goes before the statement that stores the pending
        # stack value, without storing it: reads have no side effects and
        # nothing is written in between, so reading earlier reads the same
        g.lines.append("    " * g.indent + f"{name} = {plain}")
        self.names[key] = name
        return name

    def write(self, g: Gen, op: Addr, expr: str) -> bool:
        """``= op``: the bit's local takes ``expr``; the image is written
        where the region ends (:meth:`end`).  False for a bit that is not
        kept (written to the image at once by the caller)."""
        if op.area not in AREAS:
            return False
        key = self._key(op)
        if key not in self.dirty and not self.here:
            # perf: no contact after it reads the bit and no other coil of
            # the run writes its byte: the image is written at once, as
            # without a run (a test and one in-place store); a local
            # loaded from the bit is out of date now
            self.names.pop(key, None)
            return False
        name = self._name(op)
        g.line(f"{name} = {expr}")
        self.names[key] = name
        self.dirty.setdefault(key, op)
        # the store at the region's end (perhaps in another piece of the
        # same function) uses them: the function's signature binds them
        g.use(op.area)
        return True

    def end(self, g: Gen) -> None:
        """Store the region's written bits into the image (after ``g``'s
        lines so far) and forget every local."""
        if self.dirty:
            by_byte: dict[tuple[str, int], list[int]] = {}
            for area, offset, bit in sorted(self.dirty):
                by_byte.setdefault((area, offset), []).append(bit)
            pad = "    " * g.indent
            for (area, offset), bits in by_byte.items():
                # perf: one unconditional byte store per byte (cheaper than
                # testing first whether a bit changed: measured with the
                # peer benchmark's boolean program)
                buf = g.use(area)
                if len(bits) == 1:
                    # one bit of the byte: a test and one in-place store
                    # (cheaper than reading, masking and or-ing the byte)
                    b = bits[0]
                    g.lines.append(f"{pad}if b{area}{offset}_{b}: {buf}[{offset}] |= {1 << b}")
                    g.lines.append(f"{pad}else: {buf}[{offset}] &= {~(1 << b) & 0xFF}")
                    continue
                parts = " | ".join(f"b{area}{offset}_{b}" + (f" << {b}" if b else "")
                                   for b in bits)
                keep = ~sum(1 << b for b in bits) & 0xFF
                # the pending stack value stays pending: it reads only
                # locals and bits that are not written here
                g.lines.append(f"{pad}{buf}[{offset}] = " + (
                    parts if keep == 0 else f"{buf}[{offset}] & {keep} | {parts}"))
        self.forget()

    def forget(self) -> None:
        """Forget every local without storing (an instruction that failed to
        compile took lines away: the program does not run)."""
        self.names.clear()
        self.dirty.clear()


__all__ = ["AREAS", "REGION_INSNS", "BitCache"]
