"""The code tables of the program block: instruction codes, memory areas,
operand widths, variable types.

Data only.  Each instruction code below was seen in a project file next to
the instruction Micro/WIN shows for it (its ladder cell, its symbol, the
network's title), is listed by the public description of the format
(wpyoga/s7-200-smart-project-file), or lies in a run of codes seen on both
sides of it (the comparisons come in runs of three, LD/A/O, for ``=``,
``<>``, ``>=``, ``<=``, ``>``, ``<``; the bit instructions in runs of three
as well).  A code that is not in :data:`OPCODES` is refused with its byte
offset rather than guessed (docs/project-files.md, "Instruction codes").
"""

from __future__ import annotations

__all__ = ["OPCODES", "AREAS", "CLASSES", "WIDTH_LETTER", "VAR_TYPES", "VAR_SECTIONS"]


def _runs() -> dict[int, str]:
    table: dict[int, str] = {}
    # LD, A, O, then their negations, then the immediate forms
    for k, base in enumerate(("", "N", "I", "NI")):
        for j, op in enumerate(("LD", "A", "O")):
            table[0x1FE + 3 * k + j] = op + base
    # comparisons: one block of 18 codes per operand type, each block the
    # six relations in this order, each relation LD/A/O
    for t, (kind, base) in enumerate((("B", 0x23A), ("W", 0x24C), ("D", 0x25E), ("R", 0x270))):
        for r, rel in enumerate(("=", "<>", ">=", "<=", ">", "<")):
            for j, op in enumerate(("LD", "A", "O")):
                table[base + 3 * r + j] = f"{op}{kind}{rel}"
    for r, rel in enumerate(("=", "<>")):      # strings: = and <> only
        for j, op in enumerate(("LD", "A", "O")):
            table[0x282 + 3 * r + j] = f"{op}S{rel}"
    return table


#: instruction code -> STL mnemonic
OPCODES: dict[int, str] = {
    **_runs(),
    0x20A: "NOT", 0x20B: "EU", 0x20D: "ED",
    # 0x210 is OLD: the one use seen is an SR box's code, LD S1, LD R,
    # NOT, A OUT, 0x210, = OUT, which is S1 OR (NOT R AND OUT).  ALD's
    # code has not been seen (docs/project-files.md)
    0x210: "OLD", 0x211: "LPS", 0x212: "LRD", 0x213: "LPP",
    0x214: "=", 0x215: "=I", 0x216: "S", 0x217: "SI", 0x218: "R", 0x219: "RI",
    0x230: "XMT", 0x231: "RCV", 0x234: "GPA", 0x235: "SPA", 0x236: "GIP", 0x237: "SIP",
    0x238: "GET", 0x239: "PUT",
    0x29E: "BTI", 0x2A0: "ITD",
    0x2BC: "CTU",
    0x2C6: "+R", 0x2D5: "+I", 0x2D6: "+D",
    # 0x2DB is *D: the one use seen is a MUL_DI box (its cell's name), whose
    # code is MOVD IN1, OUT then 0x2DB IN2, OUT, as an export writes MUL_DI
    0x2DB: "*D",
    0x2F0: "CRETI", 0x2F1: "ENI", 0x2F2: "DISI",
    0x30D: "MOVW", 0x30E: "MOVD", 0x30F: "MOVR",
    0x31C: "NEXT", 0x31D: "JMP", 0x31F: "LSCR", 0x320: "SCRT", 0x321: "SCRE",
    0x323: "CRET", 0x325: "END", 0x327: "STOP", 0x328: "WDR",
    0x357: "TON", 0x359: "TOF", 0x35A: "BITIM", 0x361: "AENO",
    0x3E9: "CALL",
    0x129: "ABSI", 0x12A: "ABSDI", 0x12B: "ABSR", 0x349: "ATT",
}

#: low byte of an operand's area code -> address prefix
AREAS: dict[int, str] = {0x01: "I", 0x02: "Q", 0x04: "AI", 0x08: "AQ", 0x10: "V",
                         0x20: "M", 0x40: "T", 0x80: "C"}
#: high byte of an operand's area code -> address prefix
CLASSES: dict[int, str] = {0x01: "HC", 0x02: "SM", 0x04: "S", 0x10: "AC", 0x20: "L"}

#: operand width code -> the letter of a byte, word or double word address
WIDTH_LETTER: dict[int, str] = {2: "B", 4: "W", 8: "D"}

#: the long type code of a local variable -> the type the export writes.
#: 0x48 (16 bits) and 0x90 (32 bits) name a size, not a signedness: the
#: reader writes WORD and DWORD for them (docs/project-files.md)
VAR_TYPES: dict[int, str] = {0x2: "BOOL", 0x40004: "BYTE", 0x48: "WORD", 0x90: "DWORD",
                             0x10: "DWORD", 0x1000: "REAL", 0x100000: "STRING"}

#: variable kind code of a local variable -> its VAR section
VAR_SECTIONS: dict[int, str] = {0: "IN", 1: "IN_OUT", 2: "OUT", 3: "TEMP"}
