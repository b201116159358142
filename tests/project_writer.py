"""Write small Micro/WIN V4 (.mwp) and SMART V2 (.smart) project files for
the tests of :mod:`plcrt.project`, from a parsed STL program.

The writer lays the sections out as the reader expects them (the program
block with each network's compiled statements and no ladder cells, the
symbol table, the data block, the CPU name) behind arbitrary leading bytes,
so the tests need no project file from elsewhere.  It encodes only what
the reader's code tables know; :func:`encodable` says whether a program
fits.  A test helper, not part of plcrt.
"""

from __future__ import annotations

import re
import struct
import zlib

from plcrt.lang import ir
from plcrt.project.codes import AREAS, CLASSES, OPCODES, VAR_SECTIONS

CODES = {m: c for c, m in OPCODES.items()}
_AREA = {p: a for a, p in AREAS.items()}
_CLASS = {p: k for k, p in CLASSES.items()}
_WIDTH = {"B": 2, "W": 4, "D": 8}
_BIT = re.compile(r"^([&*]?)(I|Q|V|M|SM|S|L)(\d+)\.([0-7])$")
_WORD = re.compile(r"^([&*]?)(I|Q|V|M|SM|S|L|AI|AQ)([BWD])(\d+)$")
_NUMBERED = re.compile(r"^(T|C|HC|AC)(\d+)$")
_KIND = {"OB": 0x3E8, "SBR": 0x3E9, "INT": 0x3EA}
_TYPE = {"BOOL": 0x2, "BYTE": 0x40004, "WORD": 0x48, "DWORD": 0x90, "REAL": 0x1000,
         "DINT": 0x90}
_SECTION = {s: k for k, s in VAR_SECTIONS.items()}


def u1(v: int) -> bytes: return struct.pack("<B", v)
def u2(v: int) -> bytes: return struct.pack("<H", v)
def u4(v: int) -> bytes: return struct.pack("<I", v & 0xFFFFFFFF)
def strl(s: str, width: int = 2) -> bytes:
    raw = s.encode("latin-1")
    return (u1 if width == 1 else u2)(len(raw)) + raw


def operand(text: str) -> bytes:
    """One compiled operand (its index and header are added by the caller)."""
    pointer = {"": 0, "&": 1, "*": 2}
    m = _BIT.match(text)
    if m:
        return _address(pointer[m[1]], 1, m[2], int(m[3]) * 8 + int(m[4]))
    m = _WORD.match(text)
    if m:
        return _address(pointer[m[1]], _WIDTH[m[3]], m[2], int(m[4]))
    m = _NUMBERED.match(text)
    if m:
        return _address(0, 4 if m[1] in "TC" else 8, m[1], int(m[2]))
    if re.fullmatch(r"SBR\d+", text):
        return u1(2) + bytes([0, 4, 0, 0]) + u2(2) + u4(int(text[3:]))
    if re.fullmatch(r"[+-]\d+", text):
        return u1(1) + bytes([2, 4, 1]) + u4(int(text)) + u1(0)
    if re.fullmatch(r"\d+", text):
        return u1(1) + bytes([1, 4, 1]) + u4(int(text)) + u1(0)
    if re.fullmatch(r"16#[0-9A-F]+", text):
        return u1(1) + bytes([4, 4, 1]) + u4(int(text[3:], 16)) + u1(0)
    if re.fullmatch(r"-?\d+\.\d+", text) and repr(struct.unpack("<f", struct.pack("<f", float(text)))[0]) == text:
        return u1(1) + bytes([7, 8, 1]) + struct.pack("<f", float(text)) + u1(0)
    raise ValueError(f"cannot encode operand {text!r}")


def _address(pointer: int, width: int, prefix: str, offset: int) -> bytes:
    area, klass = _AREA.get(prefix, 0), _CLASS.get(prefix, 0)
    return u1(2) + bytes([pointer, width, area, klass]) + u2(0) + u4(offset)


def statement(index: int, mnemonic: str, operands: tuple[str, ...]) -> bytes:
    out = u2(index) + u2(0) + u2(CODES[mnemonic]) + u2(0x101) + u2(len(operands))
    for j, text in enumerate(operands):
        out += u2(j) + u1(1) + u2(0x103) + u4(0) + u1(1) + u4(0) + operand(text)
    return out


#: a ladder cell: a normally open contact with no operand
CONTACT = (u1(0) + u1(0) + u1(0) + u2(0x103) + u2(0x14) + u1(0) + u1(3) + u1(0) + u2(0) + u1(0)
           + u2(0x101) + u2(0))


def network(index: int, net: ir.Network, drawn: bool = False) -> bytes:
    out = u2(index) + u2(0x102) + u2(4) + strl(net.title) + u1(0) + strl(net.comment)
    out += u1(1) + u2(0) + u1(0) + u2(0) + u1(2) + u4(0) + u2(0) + u2(len(net.insns))
    for i, insn in enumerate(net.insns):
        out += statement(i, insn.mnemonic, tuple(o.text for o in insn.operands))
    return out + u1(1) + (u2(1) + CONTACT if drawn else u2(0))


def variable(v: ir.VarDecl) -> bytes:
    return (u2(0) + strl(v.name) + u1(0) + u2(0x201) + u1(0) + bytes(3) + u2(0) + bytes(8)
            + u4(_TYPE[v.type]) + u1(0) + strl(v.comment) + u1(2) + u1(_SECTION[v.section])
            + bytes(7))


def block(pou: ir.Pou, smart: bool, protected: bool = False, drawn: tuple = ()) -> bytes:
    number = 0 if pou.kind == "OB" else pou.number
    out = u1(8 if smart else 7) + u2(_KIND[pou.kind]) + u2(0) + u2(number)
    out += u4(0x401 if protected else 1) + bytes(16) + (u4(0) if smart else b"")
    out += u2(0x0D if smart else 0x0A) + strl(pou.name) + u1(0) + strl(pou.title) + u1(0) + strl("")
    out += bytes(89) if smart else u1(0) + u4(0)
    out += bytes(32) + u1(0) + u2(len(pou.networks))
    for i, net in enumerate(pou.networks):
        out += network(i, net, (pou.ident, i + 1) in drawn)
    out += u1(0) + u2(len(pou.variables)) + b"".join(variable(v) for v in pou.variables)
    return out + u4(0) + u4(1) + u4(100)


def symbol_section(symbols: list[tuple[str, str, str]]) -> bytes:
    out = u1(5) + u2(1) + u1(7) + u2(0xBB8) + u2(0) + u2(0) + u2(1) + bytes(18) + u2(2)
    out += strl("USER1") + bytes(18) + u4(0xFFFFFFFF) + u2(len(symbols))
    for i, (name, address, comment) in enumerate(symbols):
        body = operand(address)[1:]           # pointer, width, area, class, 0, offset
        width, area, klass, offset = body[1], body[2], body[3], struct.unpack("<I", body[6:10])[0]
        out += u2(i) + u2(2) + strl(name) + u1(0) + bytes([1, 2, 0, width, area])
        out += u2(klass) + u1(0) + u4(offset) + u1(0) + bytes(3) + u2(0x200) + u2(0x6000)
        out += u1(0) + strl(comment) + u2(2) + strl("") + u2(0)
    return out


def data_section(rows: list[tuple[str, list[int], str]]) -> bytes:
    """rows: (V address like VB10 / VW20 / VD30, unsigned values, comment)."""
    out = u1(2) + u2(1) + u1(7) + u2(0x1388) + u2(0) + u2(0) + u2(1) + bytes(18) + u2(2)
    out += strl("USER1") + bytes(4) + strl("") + u2(0) + u2(len(rows))
    for i, (address, values, _) in enumerate(rows):
        tokens = [u2(0x0002) + u2(_WIDTH[address[1]] | 0x1000) + bytes(3) + u4(int(address[2:]))]
        tokens += [u2(0x0101) + u2(0x0104) + u4(v) + u1(0) for v in values]
        out += u2(i) + u1(2) + u1(0) + u4(0) + u1(1) + u4(0) + u4(0) + u2(0x101) + u2(len(tokens))
        out += b"".join(u2(j) + u1(1) + u2(0x103) + u4(0) + u1(1) + u4(0) + t
                        for j, t in enumerate(tokens))
    comments = [(i, c) for i, (_, _, c) in enumerate(rows) if c]
    out += u1(1) + u2(len(comments))
    out += b"".join(u2(i) + u2(0x202) + u2(35) + u2(0) + u1(0) + strl(c) for i, c in comments)
    return out + u2(0)


def stream(program: ir.Program, *, smart: bool = False,
           symbols: list[tuple[str, str, str]] = (), data: list = (),
           cpu: str = "CPU 224 REL 02.01", protected: tuple[str, ...] = (),
           drawn: tuple = (), system: bytes = b"", wizards: bytes | None = None) -> bytes:
    """The decompressed project: filler, program block, symbols, data, CPU.
    ``drawn`` lists (block, network) pairs given a ladder contact besides
    their code; ``system`` a system block (tests/sysblock_writer.py), with
    the flag byte and four time stamps that follow it; ``wizards`` is what
    follows the CPU name (default: no wizard configured,
    tests/wizard_writer.py writes them)."""
    body = b"\x10" + b"\x55" * 64                   # stands for preamble and system block
    body += system + (b"\x00" + b"\xe9\x07" * 32 if system else b"")
    body += u1(2) + u2(len(program.pous))
    body += b"".join(block(p, smart, p.ident in protected, drawn) for p in program.pous)
    body += symbol_section(list(symbols))
    body += b"\x03" + b"\x55" * 16                  # stands for the status charts
    if wizards is None:
        from wizard_writer import wizard_tail
        wizards = wizard_tail(smart)
    body += data_section(list(data)) + u1(0) + strl(cpu) + wizards
    return body


def container(body: bytes, *, smart: bool = False, declared: int | None = None,
              password: bool = False) -> bytes:
    """The project file around a decompressed ``body``."""
    length = len(body) if declared is None else declared
    packed = zlib.compress(body)
    if smart:
        head = b"SH3\0R02.04.00.00" + bytes(26) + (b"\x12\x34" + b"\x99" * 64 if password
                                                   else bytes(66))
    else:
        head = b"GJK\0R04.00" + bytes(26) + (b"\x41\x42" * 8 if password else b"\xaa\xaa\0\0" * 4)
    return head + u4(length) + packed


def project_bytes(program: ir.Program, *, smart: bool = False, **kw) -> bytes:
    return container(stream(program, smart=smart, **kw), smart=smart)


def encodable(program: ir.Program) -> bool:
    """Whether every statement and operand of ``program`` can be written."""
    try:
        for pou in program.pous:
            for v in pou.variables:
                if v.type not in _TYPE:
                    return False
            for net in pou.networks:
                for insn in net.insns:
                    statement(0, insn.mnemonic, tuple(o.text for o in insn.operands))
    except (KeyError, ValueError):
        return False
    return True
