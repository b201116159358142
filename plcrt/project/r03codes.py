"""The compiled code of a Micro/WIN V3 network, decoded into STL statements.

Data and one decoder.  Each encoding below was read off a project whose
ladder cells and own STL export show the same network
(docs/project-files.md, "Micro/WIN V3 projects"):

* a bit instruction is two bytes, big-endian: the instruction in the top
  four bits (:data:`BIT_OPS`), then the memory area (three bits,
  :data:`BIT_AREAS`), the bit (three bits) and the byte (six bits):
  ``0x30C0`` is ``AN I0.3``, ``0x6200`` is ``= Q0.0``, ``0x4B84`` is
  ``O T38`` (a timer's or counter's number is its byte times eight plus
  its bit);
* a stack instruction is one byte (:data:`ONE_BYTE`);
* a timer or counter box is six bytes (:data:`BOXES`): two bytes naming
  the box, the timer's or counter's number and the preset, each a
  big-endian 16-bit number (``A6 44 00 25 00 05`` is ``TON T37, +5``).

Anything else (another first byte, an area not in the table, a box whose
second byte differs) is refused with its offset, never guessed: the
compact encoding packs many instructions into few bits, so a near miss
would run another program.
"""

from __future__ import annotations

from typing import Callable

from ..errors import PlcError

__all__ = ["decode_network", "BIT_OPS", "BIT_AREAS", "ONE_BYTE", "BOXES"]

#: top four bits of a two-byte bit instruction -> its STL mnemonic.  0..4
#: and 6 were each seen next to their ladder cell and export line; 5 (``ON``)
#: next to a negated contact drawn parallel to the one before it
BIT_OPS: dict[int, str] = {0x0: "LD", 0x1: "LDN", 0x2: "A", 0x3: "AN", 0x4: "O",
                           0x5: "ON", 0x6: "="}
#: the memory area (bits 9..11 of a bit instruction) -> its address prefix
BIT_AREAS: dict[int, str] = {0: "I", 1: "Q", 2: "M", 5: "T", 6: "C"}
#: areas whose bit operand is a number (T38), not byte.bit
_NUMBERED = frozenset(("T", "C"))
#: one-byte instructions: ``OLD`` seen next to its export line; ``ALD``
#: where the cells draw a contact in series with two parallel contacts
#: (``LD I0.4``, ``LD I0.5``, ``O Q0.3``, 0xDC, ``= Q1.4``)
ONE_BYTE: dict[int, str] = {0xDC: "ALD", 0xDD: "OLD"}
#: (first byte, second byte) of a six-byte box -> (mnemonic, area of its
#: first operand)
BOXES: dict[tuple[int, int], tuple[str, str]] = {(0xA6, 0x44): ("TON", "T"),
                                                 (0xA8, 0x44): ("CTU", "C")}

Statement = tuple[str, tuple[str, ...]]


def _bit(word: int) -> Statement | None:
    op = BIT_OPS.get(word >> 12)
    area = BIT_AREAS.get((word >> 9) & 7)
    if op is None or area is None:
        return None
    bit, byte = (word >> 6) & 7, word & 0x3F
    text = f"{area}{byte * 8 + bit}" if area in _NUMBERED else f"{area}{byte}.{bit}"
    return op, (text,)


def decode_network(code: bytes, error: Callable[[int, str], PlcError]) -> list[Statement]:
    """The STL statements of one network's compiled ``code``; ``error(offset,
    message)`` makes the exception for a byte that is not understood
    (``offset`` counted from the start of ``code``)."""
    out: list[Statement] = []
    pos = 0
    while pos < len(code):
        first = code[pos]
        if first in ONE_BYTE:
            out.append((ONE_BYTE[first], ()))
            pos += 1
            continue
        if pos + 2 > len(code):
            raise error(pos, f"the compiled code ends inside an instruction (0x{first:02x})")
        word = first << 8 | code[pos + 1]
        box = BOXES.get((first, code[pos + 1]))
        if box is not None:
            if pos + 6 > len(code):
                raise error(pos, f"the compiled code ends inside a {box[0]} box")
            number = code[pos + 2] << 8 | code[pos + 3]
            preset = code[pos + 4] << 8 | code[pos + 5]
            preset -= 0x10000 if preset >= 0x8000 else 0
            out.append((box[0], (f"{box[1]}{number}", f"{preset:+d}")))
            pos += 6
            continue
        statement = _bit(word)
        if statement is None:
            raise error(pos, f"compiled instruction 0x{word:04x} is not one this reader "
                             "knows (Micro/WIN V3 code)")
        out.append(statement)
        pos += 2
    return out
