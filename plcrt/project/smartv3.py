"""The container of a Micro/WIN SMART V3 project (``.smartV3``): header,
decryption, and the zip archive inside it.

A SMART V3 project is a 256-byte header and a zip archive encrypted with
AES-256-GCM, its 16-byte tag at the end of the file.  The key is the
SHA-256 of the project's password; a project without a password is
encrypted under a default password that Micro/WIN SMART uses for every
such project and that the public description of the format publishes,
with the constant nonce and associated data (docs/project-files.md,
"SMART V3 projects").  :func:`open_smartv3` checks the header, refuses a
project protected by a password (the header's protection flag; its key is
the owner's password and is never searched for), decrypts with the
default key, verifies the tag, and reads the members a load needs
(program blocks, data pages, the symbol tables, the device file) into
memory by name, with bounds on the archive.

The archive is untrusted: the number of members and the size of its
directory are bounded before :mod:`zipfile` reads it, each member's
declared and actual inflated size and their total are bounded, only the
stored and deflate methods are read, and member names are only compared,
never used as paths.  What the members hold is read by :mod:`.smartv3pou`.
"""

from __future__ import annotations

import hashlib
import io
import re
import struct
import zipfile
import zlib
from dataclasses import dataclass, field

from ..errors import PlcConfigError, PlcError
from .container import MAX_STREAM
from .stream import binary_error

__all__ = ["SmartV3Archive", "is_smartv3", "open_smartv3", "member_label",
           "MAX_MEMBERS", "MAX_MEMBER", "MAX_TOTAL"]

HEADER_SIZE = 256
TAG_SIZE = 16
#: most members of the archive (a project holds a few files per block)
MAX_MEMBERS = 1024
#: largest central directory of the archive
MAX_DIRECTORY = 256 * 1024
#: largest inflated member read, and largest sum of the members read
MAX_MEMBER = MAX_STREAM
MAX_TOTAL = MAX_STREAM

#: the password Micro/WIN SMART V3 encrypts a project without password
#: with, and the nonce and associated data of every project (published in
#: the public description of the format; see docs/project-files.md)
_DEFAULT_PASSWORD = b"SMART200_V3_PRJ_KEY"
_NONCE = bytes.fromhex("95a634684a46a970ee907649")
_AAD = bytes.fromhex("4a14b3a57bc9f492eb46879462efb9c6")
_VERSION = re.compile(rb"R03\.\d\d\.\d\d\.\d\d")
#: the header's protection flag (byte 121): 1 a password, 2 none
_FLAG_AT = 121
_PROTECTED, _INVALID = 1, 0
_VIEWS = {0: "LAD", 1: "STL", 2: "FBD"}
_EOCD = b"PK\x05\x06"
_ZIP64_LOCATOR = b"PK\x06\x07"
_EOCD_SIZE = 22
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]")
#: what a member holds, by the end of its name (compared in lower case)
_KINDS = ((".poubin", "program"), (".dbbin", "data"), ("m_mglbvartables.xml", "symbols"),
          (".devproj", "device"), ("m_csystemblockdata.bin", "system"))
#: what zipfile raises on a damaged archive
_ZIP_ERRORS = (zipfile.BadZipFile, zipfile.LargeZipFile, zlib.error, EOFError, OSError,
               ValueError, struct.error, NotImplementedError, RuntimeError, IndexError,
               OverflowError, KeyError)
_HEAD, _CRYPT, _ZIP = "file header", "encrypted project", "zip archive"


@dataclass
class SmartV3Archive:
    """What the header says and the members read, by kind, in archive order."""

    file: str
    version: str
    view: str
    #: (kind, member name, bytes): kind is "program", "data", "symbols", "device"
    #: or "system"
    members: list[tuple[str, str, bytes]] = field(default_factory=list)
    #: names of the members not read (status charts, wizards, ...)
    others: list[str] = field(default_factory=list)


def is_smartv3(data: bytes) -> bool:
    """Whether ``data`` starts as a SMART V3 project (4 zero bytes, then
    ``R03.xx.xx.xx``)."""
    return data[:4] == bytes(4) and _VERSION.fullmatch(data[4:16]) is not None


def member_label(name: str) -> str:
    """A member's name as a message shows it: control characters replaced,
    at most 80 characters."""
    text = _CONTROL.sub("?", name)
    return text if len(text) <= 80 else text[:77] + "..."


def open_smartv3(data: bytes, file: str) -> SmartV3Archive:
    """Check the header of ``data`` (a whole ``.smartV3`` file), decrypt it
    and read the members a load needs.

    Raises:
        PlcConfigError: a project protected by a password, or one whose tag
            does not verify under the default key (damaged, or protected).
        PlcSyntaxError: a header or archive that is not a project's, or an
            archive past the bounds.
    """
    if len(data) < HEADER_SIZE + _EOCD_SIZE + TAG_SIZE:
        raise binary_error(file, _HEAD, len(data), "the file ends inside its header "
                           "(a SMART V3 project is a 256-byte header, an encrypted zip "
                           "and a 16-byte tag)", space="file")
    flag = data[_FLAG_AT]
    if flag == _PROTECTED:
        raise binary_error(file, _HEAD, _FLAG_AT, "the project is protected by a password; "
                           "open it in Micro/WIN SMART, remove the password and save it "
                           "again", PlcConfigError, "file")
    if flag == _INVALID:
        raise binary_error(file, _HEAD, _FLAG_AT, "the protection flag is 0, which is not "
                           "a SMART V3 project's (1 or 2)", space="file")
    version = data[4:16].decode("ascii")
    view = _VIEWS.get(data[18], f"view {data[18]}")
    # perf: imported here, not by every load of an .awl (plcrt.loader
    # imports the project reader); about 25 ms
    from cryptography.exceptions import InvalidTag
    from cryptography.hazmat.primitives.ciphers.aead import AESGCM
    key = hashlib.sha256(_DEFAULT_PASSWORD).digest()
    try:
        plain = AESGCM(key).decrypt(_NONCE, data[HEADER_SIZE:], _AAD)
    except InvalidTag:
        raise binary_error(file, _CRYPT, len(data) - TAG_SIZE, "the project's tag does not "
                           "verify under the default key: the file is damaged, or it is "
                           "protected by a password", PlcConfigError, "file") from None
    archive = SmartV3Archive(file, version, view)
    _read_members(plain, archive)
    return archive


def _zip_error(file: str, offset: int, message: str, section: str = _ZIP) -> PlcError:
    """A :class:`PlcSyntaxError` at ``offset`` of the decrypted archive."""
    return binary_error(file, section, offset, message, space="decrypted zip archive")


def _check_directory(plain: bytes, file: str) -> None:
    """Bound the archive's member count and directory size from its end
    record, before :mod:`zipfile` walks the directory."""
    at = plain.rfind(_EOCD, max(0, len(plain) - _EOCD_SIZE - 0xFFFF))
    if at < 0 or at + _EOCD_SIZE > len(plain):
        raise _zip_error(file, len(plain), "no end-of-directory record: the decrypted "
                         "project is not a zip archive")
    _sig, _disk, _start, _here, total, size, offset, _note = struct.unpack_from(
        "<IHHHHIIH", plain, at)
    # zipfile takes the counts of a zip64 record when its locator precedes
    # the end record: none is accepted, so the counts checked are its counts
    zip64 = at >= 20 and plain[at - 20:at - 16] == _ZIP64_LOCATOR
    if zip64 or total == 0xFFFF or size == 0xFFFFFFFF or offset == 0xFFFFFFFF:
        raise _zip_error(file, at, "a zip64 archive is not read (a project is far smaller)")
    if total > MAX_MEMBERS:
        raise _zip_error(file, at, f"the archive declares {total} members, more than the "
                         f"{MAX_MEMBERS} this reader accepts")
    if size > MAX_DIRECTORY:
        raise _zip_error(file, at, f"the archive's directory is {size} bytes, more than "
                         f"the {MAX_DIRECTORY} this reader accepts")


def _kind(name: str) -> str:
    low = name.lower().replace("\\", "/")
    base = low.rsplit("/", 1)[-1]
    for end, kind in _KINDS:
        if base.endswith(end):
            return kind
    return ""


def _read_members(plain: bytes, archive: SmartV3Archive) -> None:
    file = archive.file
    _check_directory(plain, file)
    try:
        box = zipfile.ZipFile(io.BytesIO(plain))
        infos = box.infolist()
    except _ZIP_ERRORS as e:
        raise _zip_error(file, 0, f"the archive is damaged ({member_label(str(e))})") from None
    if len(infos) > MAX_MEMBERS:
        raise _zip_error(file, 0, f"the archive holds {len(infos)} members, more than the "
                         f"{MAX_MEMBERS} this reader accepts")
    total = 0
    for info in infos:
        kind, label = _kind(info.filename), member_label(info.filename)
        if not kind:
            archive.others.append(label)
            continue
        section = f"zip member {label}"
        at = info.header_offset
        if info.flag_bits & 0x1:
            raise _zip_error(file, at, "an encrypted member is not read", section)
        if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
            raise _zip_error(file, at, f"compression method {info.compress_type} is not "
                             "read (only stored and deflate)", section)
        if info.file_size > MAX_MEMBER:
            raise _zip_error(file, at, f"the member declares {info.file_size} bytes, more "
                             f"than the {MAX_MEMBER} this reader inflates", section)
        total += info.file_size
        if total > MAX_TOTAL:
            raise _zip_error(file, at, f"the members declare more than the {MAX_TOTAL} "
                             "bytes this reader inflates in all", section)
        try:
            with box.open(info) as stream:
                body = stream.read(info.file_size + 1)   # bounded: one byte past the declared
        except _ZIP_ERRORS as e:
            raise _zip_error(file, at, f"the member is damaged ({member_label(str(e))})",
                             section) from None
        if len(body) != info.file_size:
            raise _zip_error(file, at, f"the member inflates to {len(body)} bytes or more, "
                             f"not the {info.file_size} it declares", section)
        archive.members.append((kind, info.filename, body))
