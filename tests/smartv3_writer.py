"""Write small Micro/WIN SMART V3 (.smartV3) project files for the tests of
:mod:`plcrt.project.smartv3`, from a parsed STL program.

Each block becomes a ``.poubin`` member in the V3 layout the reader
expects (block layout 0x83, networks of layout 7 whose address operands
end with 2 bytes, the local variable table as XML, a record per
network), the symbols an XML symbol table, the data block a data page
member; the archive is zipped and encrypted under the published default
key, behind the 256-byte header.  Every part can be swapped, so the tests
build damaged or hostile archives from it.  A test helper, not part of
plcrt.
"""

from __future__ import annotations

import hashlib
import io
import zipfile
from xml.sax.saxutils import quoteattr

from cryptography.hazmat.primitives.ciphers.aead import AESGCM

from plcrt.lang import ir
from project_writer import CODES, CONTACT, _KIND, _WIDTH, operand, strl, u1, u2, u4

NONCE = bytes.fromhex("95a634684a46a970ee907649")
AAD = bytes.fromhex("4a14b3a57bc9f492eb46879462efb9c6")
DEFAULT_KEY = hashlib.sha256(b"SMART200_V3_PRJ_KEY").digest()
_KIND_FB = 0x3EB
_SECTION = {"IN": 0, "IN_OUT": 1, "OUT": 2, "TEMP": 3}


def v3_operand(text: str, tail: bool = True) -> bytes:
    """A compiled operand in a V3 network: an address ends with 2 bytes (1)."""
    body = operand(text)
    return body + (u2(1) if body[0] == 2 and tail else b"")


def statement(index: int, mnemonic: str, operands: tuple[str, ...], tail: bool = True,
              code: int | None = None) -> bytes:
    out = u2(index) + u2(0) + u2(CODES[mnemonic] if code is None else code) + u2(0x101)
    out += u2(len(operands))
    for j, text in enumerate(operands):
        out += u2(j) + u1(1) + u2(0x103) + u4(0) + u1(1) + u4(0) + v3_operand(text, tail)
    return out


def contact(text: str, layout: int) -> bytes:
    """A ladder cell: a normally open contact naming ``text``, its operand of
    ``layout`` 3 or 4 (4: an address ends with 2 bytes (1))."""
    head = u1(0) + u1(0) + u1(0) + u2(0x103) + u2(0x14) + u1(0) + u1(3) + u1(0) + u2(0)
    body = operand(text) + (u2(1) if layout == 4 and operand(text)[0] == 2 else b"")
    return (head + u1(0) + u2(0x101) + u2(1)
            + u2(0) + u1(1) + u1(layout) + u1(1) + u4(0) + u1(1) + u4(0) + body)


def network(index: int, net: ir.Network, *, tail: bool = True, code: int | None = None,
            drawn: bool = False, encoding: str = "latin-1", cells: tuple = ()) -> bytes:
    out = (u2(index) + u2(0x102) + u2(7) + _text(net.title, encoding) + u1(0)
           + _text(net.comment, encoding))
    out += u1(2) + u4(0) + u1(2) + u4(0) + u1(2) + u4(0) + u2(0) + u2(len(net.insns))
    for i, insn in enumerate(net.insns):
        out += statement(i, insn.mnemonic, tuple(o.text for o in insn.operands), tail,
                         code if i == 0 else None)
    if cells:
        return out + u1(1) + u2(len(cells)) + b"".join(contact(t, k) for t, k in cells)
    return out + u1(1) + (u2(1) + CONTACT if drawn else u2(0))


def variables_xml(pou: ir.Pou) -> bytes:
    rows = ['<Member Name="EN" DataType="BOOL" varType="0"/>'] if pou.kind == "SBR" else []
    for v in pou.variables:
        rows.append(f"<Member Name={quoteattr(v.name)} DataType={quoteattr(v.type)} "
                    f'varType="{_SECTION[v.section]}" Commt={quoteattr(v.comment)}/>')
    rows.append('<Member ExtendedDataType="0" sFlags="171" varType="3"/>')
    return ('<?xml version="1.0"?>\r\n<LocVarTable>' + "".join(rows)
            + "</LocVarTable>\r\n").encode("utf-8")


def pou(block: ir.Pou, *, layout: int = 0x83, flags: int = 1, kind: int | None = None,
        tail: bool = True, code: int | None = None, xml: bytes | None = None,
        encoding: str = "latin-1", cells: tuple = ()) -> bytes:
    """One ``.poubin`` member; ``cells`` (operand, layout) are drawn in its
    first network."""
    number = 0 if block.kind == "OB" else block.number
    nets = block.networks
    out = u1(8) + u2(_KIND[block.kind] if kind is None else kind) + u2(0) + u2(number)
    out += u4(flags) + bytes(16) + u4(1) + u2(layout)
    out += _text(block.name, encoding) + u1(0) + _text(block.title, encoding) + u1(0)
    out += u2(0) + bytes(2 + 20 + 64) + u4(0) + u4(0) + bytes(3)      # author, protection
    out += bytes(32) + u1(0) + u2(len(nets))
    for i, net in enumerate(nets):
        out += network(i, net, tail=tail, code=code, encoding=encoding,
                       cells=cells if i == 0 else ())
    table = variables_xml(block) if xml is None else xml
    out += u4(0) + u4(1) + u4(100) + u1(8) + u2(0) + u4(0) + u2(1) + bytes(22)
    out += u4(len(table)) + table
    if layout != 0x82:                         # V3.1 on: a record of cell labels per network
        out += u2(0x101) + u4(len(nets)) + (u1(2) + u4(1) + u1(4) + u4(0)) * len(nets)
    return out


def _text(text: str, encoding: str) -> bytes:
    raw = text.encode(encoding)
    return u2(len(raw)) + raw


def data_page(rows: list[tuple[str, list[int], str]], index: int = 0) -> bytes:
    """One ``.dbbin`` member (a page of version 8): rows are (VB10/VW20/VD30,
    unsigned values, comment)."""
    out = u1(8) + u2(0x1388) + u2(0) + u2(index) + u2(1) + bytes(22) + u2(5)
    out += strl(f"Page_{index + 1}") + bytes(4) + strl("") + bytes(86) + u2(len(rows))
    for i, (address, values, _) in enumerate(rows):
        tokens = [u2(0x0002) + u2(_WIDTH[address[1]] | 0x1000) + bytes(3) + u4(int(address[2:]))]
        tokens += [u2(0x0101) + u2(0x0104) + u4(v) + u1(0) for v in values]
        out += u2(i) + u1(2) + u1(1) + u4(0) + u1(1) + u4(0) + u4(0) + u2(0x101) + u2(len(tokens))
        out += b"".join(u2(j) + u1(1) + u2(0x103) + u4(0) + u1(1) + u4(0) + t
                        for j, t in enumerate(tokens))
    comments = [(i, c) for i, (_, _, c) in enumerate(rows) if c]
    out += u1(2) + u4(len(comments))
    out += b"".join(u4(i) + u2(0x202) + u4(0) + u1(0) + strl(c) for i, c in comments)
    return out + u2(0)


def symbols_xml(symbols: list[tuple[str, str, str]], extra: str = "") -> bytes:
    rows = "".join(f"<Member Name={quoteattr(n)} AccessName={quoteattr(n)} DataType=\"BOOL\" "
                   f"Bind=\"1\" Addr={quoteattr(a)} Commt={quoteattr(c)}/>"
                   for n, a, c in symbols)
    return ('<?xml version="1.0" encoding="UTF-8"?>\r\n<tables><VarTable TableType="VT" '
            f'TableName="Table 1">{rows}<Member sFlags="8"/></VarTable>{extra}'
            '<VarTable TableType="IOS" TableName="I/O"><Member Name="CPU_In0" Addr="I0.0"/>'
            "</VarTable></tables>").encode("utf-8")


def members(program: ir.Program, *, symbols: list = (), data: list = (),
            cpu: str = "CPU ST40", system: bytes = bytes(64), **kw) -> list[tuple[str, bytes]]:
    """(name, bytes) of the archive's members, in the order Micro/WIN writes
    them (Windows separators); ``system`` the system block's member
    (tests/sysblock_writer.py writes one; the default is not one)."""
    out = [("p\\m_cSystemBlockData.bin", system)]
    if data:
        out.append(("p\\Data Block\\Page_1.dbbin", data_page(list(data))))
    out.append(("p\\m_mGlbVarTables.xml", symbols_xml(list(symbols))))
    out += [(f"p\\Program Block\\{p.name}.poubin", pou(p, **kw)) for p in program.pous]
    out.append(("p\\p.devproj", f'<?xml version="1.0"?>\r\n<device DeviceType="{cpu}"/>'
                .encode()))
    out.append(("p.smartprojs", b'<?xml version="1.0"?><projects/>'))
    return out


def zip_bytes(entries: list[tuple[str, bytes]], method: int = zipfile.ZIP_DEFLATED) -> bytes:
    """The archive of ``entries``, byte for byte the same for the same
    entries (fixed time stamps)."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", method) as box:
        for name, body in entries:
            box.writestr(zipfile.ZipInfo(name, (2024, 1, 1, 0, 0, 0)), body, method)
    return buffer.getvalue()


def header(*, protected: bool = False, version: bytes = b"R03.01.00.00") -> bytes:
    return (bytes(4) + version + bytes(2) + u1(0) + bytes(102) + u1(1 if protected else 2)
            + bytes(134))


def encrypt(plain: bytes, key: bytes = DEFAULT_KEY, **kw) -> bytes:
    """The project file around the zip ``plain``: header, ciphertext, tag."""
    return header(**kw) + AESGCM(key).encrypt(NONCE, plain, AAD)


def project_bytes(program: ir.Program, **kw) -> bytes:
    head = {k: kw.pop(k) for k in ("protected", "version") if k in kw}
    return encrypt(zip_bytes(members(program, **kw)), **head)
