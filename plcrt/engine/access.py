"""Reading, writing and forcing the memory image by address: the slow,
checked path that tests, the CLI, the debugger and traces use (never the
generated code, which indexes the image directly).

:class:`AddressAccess` is a mixin of :class:`plcrt.engine.runtime.Plc`; it
needs the PLC's ``mem``, ``model``, ``symbols``, ``forces`` and
``_force_slots``.  Forcing follows the System Manual ("Forcing specific
values"): a forced value is applied after the inputs are read and again
before the outputs are written.
"""

from __future__ import annotations

import struct
from typing import Any, Callable, Sequence

from ..compiler.operands import Addr, OperandError, parse_operand
from ..compiler.rt import CODECS
from ..errors import PlcAddressError, PlcError
from ..safetext import excerpt, printable
from .values import check_address, check_value, split_format


class AddressAccess:
    """Address-level access to a PLC's memory image (see the module doc)."""

    mem: Any
    model: Any
    symbols: Any
    forces: dict[str, int | float]
    _force_slots: list[tuple[bytearray, int, int, int, int | float]]

    # -- address access (slow path, for tests, CLI and tools) -------------
    def _addr(self, address: str) -> Addr:
        text = check_address(address)
        try:
            op = parse_operand(text, self.model)
        except OperandError as e:
            raise PlcAddressError(str(e)) from None
        if not isinstance(op, Addr):
            from ..compiler.resolve import Resolver
            try:
                op = Resolver(self.model, self.symbols, _system_symbols()).parse(text)
            except Exception as e:  # noqa: BLE001 - reported as an address error
                raise PlcAddressError(f"{excerpt(address)!r}: {e}") from None
        if not isinstance(op, Addr):
            raise PlcAddressError(_unknown_name(text, self.symbols))
        return op

    def locate(self, spec: str) -> tuple[bytearray, int, int, int, str]:
        """Where an address spec lives: ``(buffer, byte offset, width, bit,
        kind)``, width 0 for a bit, kind ``"bit"``, ``"int"`` or ``"real"``.

        ``spec`` is an address or symbol with an optional suffix: ``:REAL``
        reads a double word as a float, ``:BIT`` the bit of a timer or
        counter (``T37:BIT``); ``T37`` alone is its current value.
        """
        text, kind = split_format(spec)
        return self._where(text, kind, spec)

    def _where(self, text: str, kind: str, spec: str
               ) -> tuple[bytearray, int, int, int, str]:
        """:meth:`locate` of an address and a checked format."""
        a = self._addr(text)
        if kind == "BIT":
            if a.area not in ("T", "C"):
                raise PlcAddressError(f"{spec!r}: ':BIT' is for timers and counters "
                                      f"(T37:BIT, C5:BIT); a bit address needs no suffix")
            a = Addr(a.area, a.offset, 0, 0, a.text)
        buf, off, width, bit = self._locate(a)
        if kind == "REAL" and (width != 4 or a.area in ("T", "C")):
            raise PlcAddressError(f"{spec!r}: a REAL needs a double word (VD, MD, ...)")
        return buf, off, width, bit, ("real" if kind == "REAL" else
                                      "bit" if width == 0 else "int")

    def reader(self, spec: str) -> tuple[str, Callable[[], int | float]]:
        """``(kind, read)`` for a spec as in :meth:`locate`: ``read()``
        returns the value now, resolved once (for per-scan use by traces,
        watch lists and test conditions)."""
        buf, off, width, bit, kind = self.locate(spec)
        # perf: closures over the buffer and offset; nothing is parsed per read
        if kind == "real":
            unpack = CODECS["_rf"]
            return kind, lambda: unpack(buf, off)[0]
        if width == 0:
            return kind, lambda: buf[off] >> bit & 1
        if width == 1:
            return kind, lambda: buf[off]
        unpack = _SIGNED[width]
        return kind, lambda: unpack(buf, off)[0]

    def __getitem__(self, address: str) -> int | float:
        return self.read(address)

    def __setitem__(self, address: str, value: int | float | bool) -> None:
        self.write(address, value)

    def read(self, address: str, kind: str | None = None) -> int | float:
        """Read an address: bits 0/1, bytes unsigned, words/dwords signed,
        ``T37``/``C5`` their current value; ``kind="REAL"`` (or the suffix
        ``"VD4:REAL"``) reads a float, ``kind="BIT"`` the timer or counter
        bit of ``T37``/``C5`` (the formats of :data:`plcrt.engine.values.FORMATS`).

        Raises:
            PlcAddressError: a bad address, or an unknown or unfitting format.
        """
        text, fmt = split_format(address, kind)
        buf, off, width, bit, k = self._where(text, fmt, f"{text}:{fmt}" if fmt else text)
        if k == "real":
            return CODECS["_rf"](buf, off)[0]
        if width == 0:
            return buf[off] >> bit & 1
        if width == 1:
            return buf[off]
        return _SIGNED[width](buf, off)[0]

    def write(self, address: str, value: int | float | bool) -> None:
        """Write an address.  Writing an input sets the physical input too,
        so it keeps its value over the next scans (a switch left on).

        Raises:
            PlcAddressError: a bad address, a value the location cannot hold
                (:func:`plcrt.engine.values.check_value`), or SMB0, which the
                CPU sets at every scan.
        """
        a, (buf, off, width, bit), value = self._writable(address, value)
        _store(buf, off, width, bit, value)
        if a.area == "I":
            _store(self.mem.areas["PI"], off, width, bit, value)

    def _writable(self, address: str, value: Any
                  ) -> tuple[Addr, tuple[bytearray, int, int, int], int | float]:
        """The address, location and checked value of a write or force.

        SMB0 (SM0.0 to SM0.7) is refused: the CPU sets it at the start of
        every scan (System Manual, "Special memory bits", SMB0), so a written
        value would be lost unseen by the program.
        """
        a = self._addr(address)
        loc = self._locate(a)
        if loc[0] is self.mem.areas["SM"] and loc[1] == 0:
            raise PlcAddressError(
                f"{printable(address.strip())}: SMB0 (SM0.0 always on, SM0.1 first scan, "
                f"SM0.4/SM0.5 clocks, SM0.6 scan clock, SM0.7 RUN switch) is set by the "
                f"CPU at the start of every scan and cannot be written or forced")
        return a, loc, check_value(printable(address.strip()), loc[2], value)

    # -- forcing (System Manual, "Forcing specific values") ----------------
    def force(self, address: str, value: int | float | bool) -> None:
        """Force an address to a value until :meth:`unforce`.

        As on the S7-200 the forced value is written into the image at the
        start of every scan (after the inputs are read) and again after the
        program has run (before the outputs are written), so the program
        cannot change what the terminals and the next scan see.  A program
        write in between is visible to the rest of that scan, as on the CPU.

        A force belongs to the memory location, not to its spelling: with
        the symbol ``Start`` for ``I0.0``, ``force("Start", 1)`` and then
        ``force("i0.0", 0)`` leave one force (I0.0 = 0, listed in
        :attr:`forces` under the name used last), and ``unforce`` by either
        name releases it.  Overlapping locations of different sizes
        (``QB0`` and ``Q0.0``) are separate forces, applied in the order
        they were made.
        """
        _, loc, value = self._writable(address, value)
        buf, off, width, bit = loc
        old = self._forced_key(loc)
        if old is not None:
            del self.forces[old]
        self.forces[check_address(address)] = value
        self._force_slots = [s for s in self._force_slots if not _same_loc(s, loc)]
        self._force_slots.append((buf, off, width, bit, value))
        self._replain()
        _store(buf, off, width, bit, value)

    def unforce(self, address: str | None = None) -> str | None:
        """Release the force of one address, named by the symbol or the
        address it was forced by, or release all (``None``); the value stays
        until the program changes it.  Returns the name the force was
        listed under in :attr:`forces` (None when all were released).

        Raises:
            PlcAddressError: a bad address, or one that is not forced.
        """
        if address is None:
            self.forces.clear()
            self._force_slots = []
            self._replain()
            return None
        loc = self._locate(self._addr(address))
        key = self._forced_key(loc)
        if key is None:
            raise PlcAddressError(f"{printable(address.strip())} is not forced")
        del self.forces[key]
        self._force_slots = [s for s in self._force_slots if not _same_loc(s, loc)]
        self._replain()
        return key

    def _replain(self) -> None:
        """Called whenever the forces change (the PLC decides from them,
        among others, whether a scan can take its plain path)."""

    def _forced_key(self, loc: tuple[bytearray, int, int, int]) -> str | None:
        """The key of :attr:`forces` that forces location ``loc``, if any."""
        for key in self.forces:
            if _same_loc(self._locate(self._addr(key)), loc):
                return key
        return None

    def _apply_forces(self) -> None:
        for buf, off, width, bit, value in self._force_slots:
            _store(buf, off, width, bit, value)

    def _locate(self, a: Addr) -> tuple[bytearray, int, int, int]:
        """(buffer, byte offset, width, bit) of an address; T/C by name
        give their current value (as Micro/WIN's status chart shows)."""
        m = self.mem.areas
        if a.area in ("T", "C"):
            if a.width == 0:
                return m["TB" if a.area == "T" else "CB"], a.offset >> 3, 0, a.offset & 7
            return m["TV" if a.area == "T" else "CV"], a.offset * 2, 2, 0
        if a.area in ("AC", "HC"):
            return m[a.area], a.offset * 4, 4, 0
        return m[a.area], a.offset, a.width or 0, a.bit


#: big-endian signed decoders of words and double words
_SIGNED = {2: struct.Struct(">h").unpack_from, 4: struct.Struct(">i").unpack_from}


def force_covers(plc: Any, spec: str) -> bool:
    """Whether a forced address overlaps ``spec`` (forcing Q0.0 marks QB0
    too: part of what it shows cannot change), as Micro/WIN's status chart
    marks a forced value; False for an address that does not resolve.
    The debugger's and the panel's watch tables mark their rows with it."""
    if not plc.forces:
        return False
    try:
        buf, off, width, bit = plc.locate(spec)[:4]
    except PlcError:
        return False
    for key in plc.forces:
        fbuf, foff, fwidth, fbit = plc.locate(key)[:4]
        if fbuf is not buf:
            continue
        if width == 0 and fwidth == 0:
            if off == foff and bit == fbit:
                return True
        elif off < foff + max(fwidth, 1) and foff < off + max(width, 1):
            return True
    return False


def _same_loc(a: Sequence[Any], b: Sequence[Any]) -> bool:
    """Whether two (buffer, offset, width, bit) locations are the same: the
    buffers must be the same object (``==`` on bytearrays compares their
    contents, and the I and Q images are equal while both are all zeros)."""
    return a[0] is b[0] and a[1] == b[1] and a[2] == b[2] and a[3] == b[3]


def _store(b: bytearray, off: int, width: int, bit: int, value: int | float) -> None:
    if width == 0:
        if value:
            b[off] |= 1 << bit
        else:
            b[off] &= ~(1 << bit) & 0xFF
    elif isinstance(value, float):
        CODECS["_wf"](b, off, value)
    else:
        b[off:off + width] = (value & ((1 << 8 * width) - 1)).to_bytes(width, "big")


def _unknown_name(name: str, symbols: Any) -> str:
    """What to say of a name that is neither an address nor a symbol: the
    table it is missing from and the closest names there (a typo is the
    usual cause)."""
    import difflib
    names = list(symbols.entries) if symbols is not None else []
    names += [n for n in _system_symbols() if n not in names]
    close = difflib.get_close_matches(name, names, n=3, cutoff=0.6)
    where = "is not an address and not in the symbol table" if symbols is not None else \
        "is not an address"
    hint = ("; did you mean " + " or ".join(repr(excerpt(c)) for c in close) + "?") if close else ""
    return f"{excerpt(name)!r} {where}{hint}"


def _system_symbols() -> dict[str, str]:
    from ..lang.symbols import SYSTEM_SYMBOLS
    return dict(SYSTEM_SYMBOLS)
