"""The container of a project file: header, password, compressed stream.

A Micro/WIN or Micro/WIN SMART project file is a short header followed by
one zlib stream holding the project.  :func:`open_container` checks the
header, refuses a project with a password (the stream is not encrypted,
but a password is the owner's wish that the project is not read without
it), and inflates the stream with a bound: never more than the length the
header declares, and never more than :data:`MAX_STREAM` bytes, whatever
the header says (a small file cannot inflate into gigabytes).

=============  ==========  =====================  ==============  ======
signature      version     password               length at       stream
=============  ==========  =====================  ==============  ======
``GJK\\0``      ``R04.00``  16 bytes at 0x24       0x34            0x38
``GJK\\0``      ``R03.10``  (not read)             0x10            0x14
``SH3\\0``      ``R02.xx``  salt 0x2a, SHA-512     0x6c            0x70
``DEM\\0``      ``R01.xx``  salt 0x2a, SHA-1       0x40            0x44
=============  ==========  =====================  ==============  ======

It reads the header and the stream, nothing of what the stream holds.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass

from ..errors import PlcConfigError
from .stream import binary_error

__all__ = ["Container", "open_container", "MAX_STREAM"]

#: largest decompressed project accepted (real projects are 10 KB to a
#: few MB; the largest S7-200 program is 24 KB of code)
MAX_STREAM = 16 * 1024 * 1024

#: (signature, version prefix) -> (format, password field, length offset)
_LAYOUTS = {
    (b"GJK\0", b"R04."): ("Micro/WIN V4", (0x24, 16), 0x34),
    (b"GJK\0", b"R03."): ("Micro/WIN V3", None, 0x10),
    (b"SH3\0", b"R02."): ("Micro/WIN SMART V2", (0x2A, 66), 0x6C),
    (b"DEM\0", b"R01."): ("Micro/WIN SMART V1", (0x2A, 22), 0x40),
}
#: the password field of a Micro/WIN V4 project without a password
_V4_NO_PASSWORD = b"\xaa\xaa\0\0" * 4
_HEADER = "file header"


@dataclass(frozen=True)
class Container:
    """What the header says and the inflated stream."""

    file: str
    format: str
    version: str
    stream: bytes
    #: offset of the stream in the file (errors in it are counted from there)
    stream_offset: int


def open_container(data: bytes, file: str, max_stream: int = MAX_STREAM) -> Container:
    """Check the header of ``data`` (a whole project file) and inflate its
    stream.

    Raises:
        PlcSyntaxError: a header or stream that is not a project's,
            truncated, or inflating to more than it declares.
        PlcConfigError: a bare zip archive or a project with a password
            (SMART V3 projects are opened by :mod:`.smartv3`).
    """
    if data[:2] == b"PK":
        raise binary_error(file, _HEADER, 0, "a bare zip archive, not a project file (a "
                           "Micro/WIN SMART V3 project is a 256-byte header and an encrypted "
                           "zip)", PlcConfigError, "file")
    layout = _LAYOUTS.get((data[:4], data[4:8]))
    if layout is None:
        raise binary_error(file, _HEADER, 0, "not a Micro/WIN V4 (.mwp) or Micro/WIN "
                           "SMART V2 (.smart) project: unknown signature or version",
                           space="file")
    fmt, password, at = layout
    end = data.find(b"\0", 4, 20)
    version = data[4:end if end > 0 else 16].decode("ascii", "replace")
    if len(data) < at + 6:
        raise binary_error(file, _HEADER, len(data), "the file ends inside its header",
                               space="file")
    if password is not None and _has_password(data, fmt, *password):
        raise binary_error(file, _HEADER, password[0], "the project is protected by a "
                           "password; open it in Micro/WIN, remove the password and "
                           "save it again", PlcConfigError, "file")
    length = struct.unpack_from("<I", data, at)[0]
    if length > max_stream:
        raise binary_error(file, _HEADER, at, f"the project declares {length} bytes, more "
                           f"than the {max_stream} this reader inflates", space="file")
    start = at + 4
    inflater = zlib.decompressobj()
    try:
        stream = inflater.decompress(data[start:], length + 1)
    except zlib.error as e:
        raise binary_error(file, "compressed stream", _failed_at(data, start),
                           f"the compressed stream is damaged ({e})",
                           space="file") from None
    if len(stream) != length or not inflater.eof:
        got = "more" if len(stream) > length else f"{len(stream)}"
        raise binary_error(file, "compressed stream", len(data),
                           f"the stream inflates to {got} bytes, not the {length} its "
                           "header declares", space="file")
    return Container(file, fmt, version, stream, start)


def _has_password(data: bytes, fmt: str, offset: int, size: int) -> bool:
    field = data[offset:offset + size]
    if fmt == "Micro/WIN V4":
        return field != _V4_NO_PASSWORD and any(field)
    return any(field)


def _failed_at(data: bytes, start: int) -> int:
    """The offset (in the file) of the first byte zlib refuses, found by
    bisection over prefixes, each inflated to at most 64 KiB."""
    lo, hi = 0, len(data) - start
    while lo < hi:            # the shortest prefix that already fails
        mid = (lo + hi) // 2
        try:
            zlib.decompressobj().decompress(data[start:start + mid + 1], 1 << 16)
        except zlib.error:
            hi = mid
        else:
            lo = mid + 1
    return start + lo
