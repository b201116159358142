"""The SDO server of a simulated drive on CAN (CiA 301 §7.2.4).

What it is: :class:`SdoServer`, the protocol of one server SDO as bytes in and
bytes out: expedited and segmented download and upload, abort.  Every request
is answered from the drive's own objects through two callables, ``read(index,
sub) -> bytes`` and ``write(index, sub, data)``, which raise
:class:`~.od.SdoAbort` with the drive's code (a subindex the object lacks is
0x06090011, an object the drive lacks 0x06020000: nothing is answered from a
library's store).  Block transfers (CiA 301 §7.2.4.3.9–16) are refused with
0x05040001 (command specifier not valid), which a client takes as "use
segmented transfer".  A frame that is not 8 bytes long is no SDO request
(CiA 301 §7.2.4.3: every SDO frame has 8 data bytes) and is not answered.

What it is not: no CAN access (the port sends the answer), no object rules.
"""

from __future__ import annotations

import struct
from typing import Callable, Optional

from .od import SdoAbort

__all__ = ["SdoServer", "MAX_SEGMENTED"]

#: The longest segmented download accepted (bytes): the drive's longest object
#: is a short string; a bound keeps an untrusted client from growing a buffer.
MAX_SEGMENTED = 1024
_HEAD = struct.Struct("<BHB")
_ABORT = struct.Struct("<BHBI")
_INVALID_CS = 0x05040001
_TOGGLE = 0x05030000


class SdoServer:
    """One server SDO over *read* / *write* (see the module docstring)."""

    def __init__(self, read: Callable[[int, int], bytes],
                 write: Callable[[int, int, bytes], None],
                 refused: Optional[Callable[[SdoAbort], None]] = None) -> None:
        """*refused*: told of every abort *read*/*write* raise (the port logs it)."""
        self.read = read
        self.write = write
        self.refused = refused
        self._index = 0
        self._sub = 0
        self._mode = ""            # "up" / "down" while a segmented transfer is open
        self._buf = bytearray()
        self._size: Optional[int] = None
        self._toggle = 0

    def request(self, data: bytes) -> Optional[bytes]:
        """The answer to one request frame (None: not answered).

        Raises:
            Exception: only what *read*/*write* raise other than
                :class:`SdoAbort` (the port logs it and sends 0x08000000 via
                :meth:`abort`)."""
        if len(data) != 8:
            return None
        cs = data[0] >> 5
        try:
            if cs == 1:
                return self._init_download(data)
            if cs == 0:
                return self._segment_download(data)
            if cs == 2:
                return self._init_upload(data)
            if cs == 3:
                return self._segment_upload(data)
            if cs == 4:                      # the client aborts: nothing is answered
                self._mode = ""
                return None
            if cs in (5, 6):                 # block download / upload initiate
                _, self._index, self._sub = _HEAD.unpack_from(data)
            return self.abort(_INVALID_CS)
        except SdoAbort as e:
            if self.refused is not None:
                self.refused(e)
            return self.abort(e.code)

    def abort(self, code: int) -> bytes:
        """An abort frame for the transfer in hand."""
        self._mode = ""
        return _ABORT.pack(0x80, self._index, self._sub, code)

    # ---------------------------------------------------------------- download
    def _init_download(self, data: bytes) -> bytes:
        cmd, index, sub = _HEAD.unpack_from(data)
        self._index, self._sub, self._mode = index, sub, ""
        if cmd & 0x02:                       # expedited
            size = 4 - ((cmd >> 2) & 3) if cmd & 0x01 else 4
            self.write(index, sub, bytes(data[4:4 + size]))
        else:
            self._size = struct.unpack_from("<I", data, 4)[0] if cmd & 0x01 else None
            if self._size is not None and self._size > MAX_SEGMENTED:
                return self.abort(0x05040005)
            self._mode, self._buf, self._toggle = "down", bytearray(), 0
        return _HEAD.pack(0x60, index, sub) + bytes(4)

    def _segment_download(self, data: bytes) -> bytes:
        cmd = data[0]
        if self._mode != "down":
            return self.abort(_INVALID_CS)
        if cmd & 0x10 != self._toggle:
            return self.abort(_TOGGLE)
        self._buf += data[1:8 - ((cmd >> 1) & 7)]
        if len(self._buf) > MAX_SEGMENTED:
            return self.abort(0x05040005)
        answer = bytes([0x20 | self._toggle]) + bytes(7)
        self._toggle ^= 0x10
        if cmd & 0x01:                       # the last segment
            self._mode = ""
            if self._size is not None and self._size != len(self._buf):
                return self.abort(0x06070010)
            self.write(self._index, self._sub, bytes(self._buf))
        return answer

    # ---------------------------------------------------------------- upload
    def _init_upload(self, data: bytes) -> bytes:
        _, index, sub = _HEAD.unpack_from(data)
        self._index, self._sub, self._mode = index, sub, ""
        value = self.read(index, sub)
        if len(value) <= 4:
            return (_HEAD.pack(0x43 | (4 - len(value)) << 2, index, sub)
                    + value + bytes(4 - len(value)))
        self._mode, self._buf, self._toggle = "up", bytearray(value), 0
        return _HEAD.pack(0x41, index, sub) + struct.pack("<I", len(value))

    def _segment_upload(self, data: bytes) -> bytes:
        cmd = data[0]
        if self._mode != "up":
            return self.abort(_INVALID_CS)
        if cmd & 0x10 != self._toggle:
            return self.abort(_TOGGLE)
        chunk, self._buf = self._buf[:7], self._buf[7:]
        last = not self._buf
        answer = bytes([self._toggle | (7 - len(chunk)) << 1 | last]) + chunk \
            + bytes(7 - len(chunk))
        self._toggle ^= 0x10
        if last:
            self._mode = ""
        return answer
