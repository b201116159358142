"""Library CALL sites of blocks that declare ``exact_results``
(plcrt.blocks.call): the results are unpacked into locals and those the
block keeps within their type are written without a mask.

Pinned here: such a site writes exactly the bytes a masked site writes for
every value in range (signed and unsigned, at the edges of each type); a
value out of range is a run-time fault, never a silently wrapped value; a
result the block does not declare is still masked (wraps); a block that
returns another number of results faults; the bits of one byte reach their
own parameters through the bit table.  Each EM253 block is run through
the seed examples and the scenarios below with every result checked
against the range it declares.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any, Iterator

import pytest

import plcrt
from plcrt.blocks import BLOCK_FACTORIES, load_libraries
from plcrt.blocks.interface import interfaces
from plcrt.compiler.rt import BITS

ROOT = Path(__file__).resolve().parents[2]
_unique = itertools.count()

#: SET_AbsPos: EmNo, AxisNo, PosSet (DINT), Start (BOOL, written), C_Status
#: (WORD): results Start and C_Status
SET = "CALL   SET_AbsPos, 0, 0, VD10, M0.0, VW20"
#: GET_AbsPos: results C_Pos (DINT) and C_Status (WORD), side by side
#: (one store) or apart (a store each)
GET = "CALL   GET_AbsPos, 0, 0, VD120, VW124"
GET_APART = "CALL   GET_AbsPos, 0, 0, VD120, VW200"
LAYOUTS = pytest.mark.parametrize("call,status_at", [(GET, "VW124"), (GET_APART, "VW200")])


def _program(*lines: str) -> str:
    # a title of its own: the compiled-program cache never hands back a
    # program compiled with another block implementation
    return "\n".join(["ORGANIZATION_BLOCK MAIN:OB1",
                      f"TITLE=exact results {next(_unique)}", "BEGIN", "Network 1",
                      "LD     SM0.0", *lines, "END_ORGANIZATION_BLOCK", ""])


class _Fixed:
    """A stand-in block returning ``out`` on every call."""

    exact_results: tuple[str, ...] | None = None
    out: tuple = ()

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        self.calls: list[tuple] = []

    def __call__(self, *args: Any) -> tuple:
        self.calls.append(args)
        return self.out


@pytest.fixture
def stand_in(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """``stand_in(NAME, out, exact)``: NAME's calls return ``out``;
    ``exact`` is its exact_results (None: the block declares nothing)."""
    load_libraries()

    def make(name: str, out: tuple, exact: tuple[str, ...] | None) -> None:
        cls = type("Fixed", (_Fixed,), {"exact_results": exact, "out": out})
        monkeypatch.setitem(BLOCK_FACTORIES, name.upper(), cls)

    yield make


def _bytes(plc: plcrt.Plc, start: int, n: int) -> bytes:
    return bytes(plc.mem.areas["V"][start:start + n])


@pytest.mark.parametrize("pos,status", [
    (0, 0), (1, 1), (-1, 65535), (2**31 - 1, 8), (-2**31, 4), (123456, 257)])
def test_exact_results_write_the_bytes_of_masked_results(stand_in: Any, pos: int,
                                                         status: int) -> None:
    """In range, the unmasked signed store and the masked store agree."""
    written = []
    for call, exact in itertools.product((GET, GET_APART),
                                         (None, (), ("C_Status",), ("C_Pos", "C_Status"))):
        stand_in("GET_AbsPos", (pos, status), exact)
        plc = plcrt.load(_program(call))
        plc["VD120"], plc["VW124"], plc["VW200"] = 0x5A5A5A5A, 0x5A5A, 0x5A5A
        plc.scan()
        written.append(_bytes(plc, 120, 4) + _bytes(plc, 124 if call == GET else 200, 2))
    assert written[0] == (pos & 0xFFFFFFFF).to_bytes(4, "big") + status.to_bytes(2, "big")
    assert written == [written[0]] * 8


@LAYOUTS
@pytest.mark.parametrize("pos", [2**31, -2**31 - 1, 2**32 + 5])
def test_an_exact_result_out_of_range_faults_instead_of_wrapping(
        stand_in: Any, pos: int, call: str, status_at: str) -> None:
    stand_in("GET_AbsPos", (pos, 1), ("C_Pos", "C_Status"))
    plc = plcrt.load(_program(call))
    with pytest.raises(plcrt.PlcRuntimeError):
        plc.scan()
    assert plc.mode == "STOP"


@LAYOUTS
@pytest.mark.parametrize("pos", [2**31, -2**31 - 1, 2**32 + 5])
def test_a_result_not_declared_exact_still_wraps(stand_in: Any, pos: int, call: str,
                                                 status_at: str) -> None:
    stand_in("GET_AbsPos", (pos, 1), ("C_Status",))
    plc = plcrt.load(_program(call))
    plc.scan()
    assert plc["VD120"] == (pos + 2**31) % 2**32 - 2**31 and plc[status_at] == 1


@LAYOUTS
@pytest.mark.parametrize("status", [65536, -1])
def test_an_exact_word_out_of_range_faults(stand_in: Any, status: int, call: str,
                                           status_at: str) -> None:
    stand_in("GET_AbsPos", (0, status), ("C_Status",))
    plc = plcrt.load(_program(call))
    with pytest.raises(plcrt.PlcRuntimeError):
        plc.scan()


@pytest.mark.parametrize("before", [0x0000, 0x0001, 0x002C, 0x0100, 0x012C, 0xFFFF, 0x2C00])
@pytest.mark.parametrize("status", [0, 1, 44, 255, 256, 300, 0x2C00, 65535])
def test_a_lone_word_result_leaves_the_word_holding_it(stand_in: Any, before: int,
                                                        status: int) -> None:
    """A lone exact WORD result is stored only when the word does not hold
    it already (the bytes 0, v for v in 0..255); whatever the word held,
    it holds the result after the call: 300 over 0x002C (its low byte) and
    0x2C00 over 0x002C are stored, 44 over 0x002C is the same bytes."""
    stand_in("GET_AbsPos", (7, status), ("C_Pos", "C_Status"))
    plc = plcrt.load(_program(GET_APART))
    for _ in range(2):                 # the second scan: the word holds it
        plc["VW200"] = before
        plc.scan()
        assert _bytes(plc, 200, 2) == status.to_bytes(2, "big")
        assert plc["VD120"] == 7


@pytest.mark.parametrize("out", [(0,), (0, 1, 2)])
def test_a_block_declaring_exact_results_must_return_them_all(stand_in: Any,
                                                              out: tuple) -> None:
    stand_in("GET_AbsPos", out, ("C_Status",))
    plc = plcrt.load(_program(GET))
    with pytest.raises(plcrt.PlcRuntimeError):
        plc.scan()


def test_exact_bool_and_word_results_of_set_abspos(stand_in: Any) -> None:
    """A written-back BOOL (Start) and a WORD, unpacked: the bit is set and
    cleared as the block says, its neighbours kept."""
    for start, status in ((1, 7), (0, 65535)):
        stand_in("SET_AbsPos", (start, status), ("Start", "C_Status"))
        plc = plcrt.load(_program(SET))
        plc["MB0"] = 0b1111_1110 | (1 - start)
        plc["VD10"] = 99
        plc.scan()
        assert plc["MB0"] == 0b1111_1110 | start
        assert plc["VW20"] == (status if status < 32768 else status - 65536)


def test_bit_table_holds_every_bit_of_every_byte() -> None:
    assert len(BITS) == 256
    assert all(BITS[v][k] == v >> k & 1 for v in range(256) for k in range(8))


@pytest.mark.parametrize("mb0", [0, 0b1, 0b10101, 0b11111, 0b11110, 0xFF])
def test_bits_of_one_byte_reach_their_own_parameters(stand_in: Any, mb0: int) -> None:
    """MOTION_EN3's five BOOL inputs from MB0, read once through the table."""
    stand_in("MOTION_EN3", (0, 0, 1), ("Clr0", "Clr1", "Status"))
    plc = plcrt.load(_program("CALL   MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4, VW0"))
    plc["MB0"] = mb0
    plc.scan()
    block = next(b for b in plc._bindings.values() if isinstance(b, _Fixed))
    assert block.calls == [(0, *(mb0 >> k & 1 for k in range(5)))]


# ---------------------------------------------------------------------------
# The EM253 blocks keep what they declare
# ---------------------------------------------------------------------------

_RANGE = {"BOOL": (0, 1), "BYTE": (0, 255), "WORD": (0, 65535), "INT": (-2**15, 2**15 - 1),
          "DWORD": (0, 2**32 - 1), "DINT": (-2**31, 2**31 - 1)}


#: the blocks the checked calls ran (a global: a PLC's bindings are copies,
#: a list a closure held would be copied with them)
_SEEN: list[str] = []


@pytest.fixture
def checked(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[str]]:
    """Every EM253 block checks each call's results against its
    exact_results; the names of the blocks called are collected."""
    from plcrt.devices.em253.base import MotionBlock
    load_libraries()
    _SEEN.clear()
    for name, factory in list(BLOCK_FACTORIES.items()):
        if not (isinstance(factory, type) and issubclass(factory, MotionBlock)):
            continue
        itf = interfaces()[factory.name.upper()]

        def call(self: Any, *args: Any, _base: Any = factory, _itf: Any = itf) -> tuple:
            out = _base.__call__(self, *args)
            _SEEN.append(_itf.name)
            assert type(out) is tuple and len(out) == len(_itf.results)
            for p, v in zip(_itf.results, out):
                if p.name in _base.exact_results:
                    lo, hi = _RANGE[p.type]
                    assert type(v) is int and lo <= v <= hi, (_itf.name, p.name, v)
            return out

        cls = type(factory.__name__, (factory,), {"__call__": call})
        monkeypatch.setitem(BLOCK_FACTORIES, name, cls)
    yield _SEEN


def _run_bits(text: str) -> list[str]:
    """The Run argument (a bit address) of every CALL that has one."""
    out = []
    for line in text.splitlines():
        if not line.startswith("CALL"):
            continue
        name, *args = [a.strip() for a in line[4:].split(",")]
        itf = interfaces().get(name.upper())
        names = [p.name for p in itf.params] if itf else []
        if "Run" in names and len(args) == len(names) and "." in args[names.index("Run")]:
            out.append(args[names.index("Run")])
    return out


def _example(name: str) -> tuple[str, Any, Any]:
    d = ROOT / "programs" / "em253"
    text = (d / name).read_text(encoding="utf-8")
    own = d / f"{Path(name).stem}_plant.toml"
    db = d / f"{Path(name).stem}.db"
    return (text.replace("TITLE=", f"TITLE=checked {next(_unique)} ", 1),
            str(own if own.is_file() else d / "plant.toml"), str(db) if db.is_file() else None)


@pytest.mark.parametrize("name", sorted(p.name for p in (ROOT / "programs" / "em253")
                                        .glob("*.awl")))
def test_em253_examples_keep_their_exact_results_in_range(checked: list[str],
                                                          name: str) -> None:
    text, plant, data = _example(name)
    plc = plcrt.load(text, plant=plant, data=data, scan_ms=1.0)
    runs = _run_bits(text)
    assert runs
    for addr in runs:
        plc[addr] = 1
    plc.run(seconds=3)
    for addr in runs:   # Run = 0: the ramps down and the stops
        plc[addr] = 0
    plc.run(seconds=3)
    assert checked and plc.mode == "RUN"


def test_full_speed_differential_and_reverse_keep_c_spd_in_range(checked: list[str]) -> None:
    """SPD_CTRL at the differential limit (500 kHz) both ways, GET_AbsPos."""
    text = _program("CALL   MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4, VW0",
                    "CALL   SPD_CTRL, 0, 0, +1, +1, +400000, +500000, VD100, VB104, "
                    "M1.1, M1.2, M1.0, VW106, VD108", GET)
    plc = plcrt.load(text, plant={"module": {"0": {"axis": {"0": {}}}}}, scan_ms=1.0)
    plc["M0.0"] = 1
    for direction in (1, 0):
        plc["M1.1"], plc["M1.0"] = direction, 1
        plc.run(seconds=0.5)
        assert abs(plc["VD108"]) == 500_000
        plc["M1.0"] = 0
        plc.run(seconds=0.5)
    assert {"SPD_CTRL", "GET_AbsPos", "MOTION_EN3"} <= set(checked)


class _Writer(_Fixed):
    """A stand-in that stores ``byte`` into MB0 during the call (as a block
    writing through a pointer may), then returns ``out``."""

    byte = 0

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        super().__init__(plc, loc, itf)
        self.m = plc.mem.areas["M"]

    def __call__(self, *args: Any) -> tuple:
        self.m[0] = self.byte
        return super().__call__(*args)


@pytest.mark.parametrize("before,during,clr", [
    (0b00000, None, (0, 0)), (0b11000, None, (1, 1)), (0b01000, None, (0, 1)),
    (0b10111, None, (1, 0)), (0b00000, 0b11000, (0, 0)), (0b11000, 0b00111, (1, 1)),
    (0b11111, 0b10000, (1, 0)), (0b01000, None, (1, 1)), (0b11000, 0b01000, (1, 1)),
    (0b00000, 0b01000, (1, 0))])
def test_written_back_bits_of_one_byte_are_those_returned(
        monkeypatch: pytest.MonkeyPatch, before: int, during: int | None,
        clr: tuple[int, int]) -> None:
    """MOTION_EN3's Clr0/Clr1 (M0.3, M0.4) written back: the byte ends with
    the returned bits and its other bits as they are after the call, also
    when the call itself changed the byte (the store is skipped only when
    the byte already holds the returned bits)."""
    load_libraries()
    attrs = {"exact_results": ("Clr0", "Clr1", "Status"), "out": (*clr, 1),
             "byte": before if during is None else during}
    monkeypatch.setitem(BLOCK_FACTORIES, "MOTION_EN3", type("W", (_Writer,), attrs))
    plc = plcrt.load(_program("CALL   MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4, VW0"))
    plc["MB0"] = before
    plc.scan()
    after_call = before if during is None else during
    assert plc["MB0"] == after_call & 0b11100111 | clr[0] << 3 | clr[1] << 4
