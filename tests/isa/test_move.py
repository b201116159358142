"""Table tests for plcrt.isa.move: MOVB/W/D/R, pointers, block moves, FILL,
SWAP and the immediate byte transfers BIR/BIW (S7-200 System Manual, "Move
instructions" and "Indirect addressing"; digest section 3.2)."""

from __future__ import annotations

import pytest

import plcrt
from stl_helpers import load_ob1 as _load, ob1_text
from plcrt.errors import PlcCompileError, PlcRuntimeError


def _run(body: str, preset: dict | None = None) -> plcrt.Plc:
    """One network ``LD SM0.0`` + ``body``, memory preset, one scan."""
    p = _load("LD SM0.0\n" + body)
    for addr, value in (preset or {}).items():
        if isinstance(value, float):
            p.write(addr, value)
        else:
            p[addr] = value
    p.scan()
    return p


MOVES = [
    ("MOVB const", "MOVB 200, VB0", {}, {"VB0": 200}),
    ("MOVB hex", "MOVB 16#7F, MB3", {}, {"MB3": 0x7F}),
    ("MOVB byte", "MOVB VB1, QB0", {"VB1": 0xA5}, {"QB0": 0xA5}),
    ("MOVB SMB read", "MOVB SMB0, VB0", {}, {"VB0": 0xCB}),   # SM0.0/.1/.3/.6/.7 first scan
    ("MOVW const", "MOVW -1234, VW0", {}, {"VW0": -1234}),
    ("MOVW odd address", "MOVW 16#1234, VW7", {}, {"VB7": 0x12, "VB8": 0x34}),
    ("MOVW big-endian", "MOVW VW0, VW10", {"VB0": 0x80, "VB1": 0x01}, {"VW10": -32767}),
    ("MOVW from T", "MOVW T37, VW0", {"T37": 321}, {"VW0": 321}),
    ("MOVW to C", "MOVW +77, C4", {}, {"C4": 77}),
    ("MOVW to AQW", "MOVW VW0, AQW2", {"VW0": 1000}, {}),
    ("MOVD const", "MOVD 16#89ABCDEF, VD0", {}, {"VD0": 0x89ABCDEF - 2**32}),
    ("MOVD dword", "MOVD VD0, MD4", {"VD0": 100000}, {"MD4": 100000}),
    ("MOVD aliasing", "MOVD VD0, VD2", {"VD0": 0x11223344}, {"VD2": 0x11223344,
                                                             "VW0": 0x1122}),
    ("MOVD to AC", "MOVD -5, AC3\nMOVD AC3, VD8", {}, {"VD8": -5}),
    ("MOVR const", "MOVR 3.25, VD0", {}, {"VD0": 0x40500000}),
    ("MOVR real", "MOVR VD0, VD4", {"VD0": -0.5}, {"VD4": -0.5}),
    ("MOVR to AC", "MOVR 1.0, AC1\nMOVD AC1, VD0", {}, {"VD0": 0x3F800000}),
    ("SWAP", "SWAP VW0", {"VW0": 0x1234}, {"VW0": 0x3412}),
    ("SWAP negative", "SWAP VW0", {"VW0": 0x00FF}, {"VW0": -256}),
]


@pytest.mark.parametrize("label,body,preset,expected", MOVES, ids=[m[0] for m in MOVES])
def test_moves(label: str, body: str, preset: dict, expected: dict) -> None:
    """MOVB/MOVW/MOVD/MOVR/SWAP copy bit patterns between every area."""
    p = _run(body, preset)
    got = {a: (p.read(a, "REAL") if isinstance(v, float) else p[a]) for a, v in expected.items()}
    assert got == expected


def test_moves_need_power_flow() -> None:
    """A move does nothing when the top of the stack is 0."""
    p = _load("LD I0.0\nMOVW +5, VW0\nMOVD +5, VD2\nMOVB 5, VB6\nMOVR 5.0, VD8")
    p.scan()
    assert [p["VW0"], p["VD2"], p["VB6"], p["VD8"]] == [0, 0, 0, 0]


ACCUMULATOR = [
    ("MOVB into AC0", "MOVD 16#11223344, AC0\nMOVB 16#AA, AC0", 0x112233AA),
    ("MOVW into AC2", "MOVD 16#11223344, AC2\nMOVW 16#BBCC, AC2", 0x1122BBCC),
    ("MOVD into AC1", "MOVD 16#11223344, AC1\nMOVD 16#01020304, AC1", 0x01020304),
    ("byte read and write", ("MOVD 16#112233F0, AC3\nMOVB AC3, VB0\nMOVD 0, AC3\n"
                             "MOVB VB0, AC3"), 0x000000F0),
]


@pytest.mark.parametrize("label,body,expected", ACCUMULATOR, ids=[a[0] for a in ACCUMULATOR])
def test_accumulator_byte_and_word_writes_touch_only_the_low_part(label: str, body: str,
                                                                  expected: int) -> None:
    """Writing a byte/word into ACn changes only its low byte/word."""
    p = _run(body)
    ac = [n for n in range(4) if f"AC{n}" in body][-1]
    assert p[f"AC{ac}"] & 0xFFFFFFFF == expected


# -- pointers -----------------------------------------------------------------
POINTERS = [
    ("*AC read word", "MOVD &VB100, AC1\nMOVW *AC1, VW0", {"VW100": 1234}, {"VW0": 1234}),
    ("*AC write word", "MOVD &VB100, AC2\nMOVW -7, *AC2", {}, {"VW100": -7}),
    ("*VD read byte", "MOVD &VB200, VD10\nMOVB *VD10, VB2", {"VB200": 77}, {"VB2": 77}),
    ("*VD write dword", "MOVD &VD300, VD10\nMOVD 16#CAFE, *VD10", {}, {"VD300": 0xCAFE}),
    ("*LD read word", "MOVD &VW300, LD0\nMOVW *LD0, VW4", {"VW300": -9}, {"VW4": -9}),
    ("pointer to M", "MOVD &MB4, AC1\nMOVB *AC1, VB0", {"MB4": 42}, {"VB0": 42}),
    ("pointer to I", "MOVD &IB1, AC1\nMOVB *AC1, VB0", {"IB1": 0x81}, {"VB0": 0x81}),
    ("pointer to T value", "MOVD &T37, AC1\nMOVW *AC1, VW0", {"T37": 55}, {"VW0": 55}),
    ("pointer to C value", "MOVD &C2, AC1\nMOVW +9, *AC1", {}, {"C2": 9}),
    ("pointer advance +2", "MOVD &VB100, AC1\n+D +2, AC1\nMOVW *AC1, VW0",
     {"VW102": 4321}, {"VW0": 4321}),
    ("pointer advance +4", "MOVD &VB100, VD20\n+D +4, VD20\nMOVD *VD20, VD0",
     {"VD104": -100000}, {"VD0": -100000}),
    ("pointer value", "MOVD &VB100, VD0", {}, {"VD0": 0x08000064}),
]


@pytest.mark.parametrize("label,body,preset,expected", POINTERS, ids=[p[0] for p in POINTERS])
def test_indirect_addressing(label: str, body: str, preset: dict, expected: dict) -> None:
    """&address builds a pointer in AC1-3/VD/LD; *AC/*VD/*LD read and write through it."""
    p = _run(body, preset)
    assert {a: p[a] for a in expected} == expected


def test_out_of_range_pointer_is_a_fatal_error_with_location() -> None:
    """A pointer past the area end raises PlcRuntimeError at the instruction; the CPU stops."""
    p = _load("LD SM0.0\n= Q0.0\nMOVD &VB100, AC1",
              "LD I0.0\n+D +100000, AC1",
              "LD SM0.0\nMOVW *AC1, VW0")
    p.scan()
    assert p.mode == "RUN" and p.mem.areas["PQ"][0] == 1
    p["I0.0"] = 1
    with pytest.raises(PlcRuntimeError) as exc:
        p.scan()
    assert "<string>:12:" in str(exc.value)
    assert exc.value.loc is not None and exc.value.loc.line == 12
    assert p.mode == "STOP"
    assert p.mem.areas["PQ"][0] == 0          # outputs off in STOP
    scans = p.scans
    p.scan(3)
    assert p.scans == scans                   # nothing runs in STOP


@pytest.mark.parametrize("body", [
    "MOVD 16#08000000, AC1\nMOVD 16#FFFFFF, AC1\nMOVB *AC1, VB0",   # offset too big
    "MOVD 16#7F000000, AC1\nMOVB *AC1, VB0",                         # unknown area code
    "MOVD &VB10239, AC1\nMOVW *AC1, VW0",                           # word runs past the end
])
def test_bad_pointers_stop_the_cpu(body: str) -> None:
    """Unknown areas and accesses that end past the area are fatal run-time errors."""
    p = _load("LD SM0.0\n" + body)
    with pytest.raises(PlcRuntimeError, match="outside memory"):
        p.scan()
    assert p.mode == "STOP"


@pytest.mark.parametrize("body", ["MOVW *AC0, VW0", "MOVB 1, *VW0", "MOVD &AC1, VD0",
                                  "MOVW &VB0, VW0"])
def test_invalid_pointer_operands_are_compile_errors(body: str) -> None:
    """AC0 cannot hold a pointer, only dwords dereference, & needs a memory address and MOVD."""
    with pytest.raises(PlcCompileError):
        _load("LD SM0.0\n" + body)


# -- block moves ------------------------------------------------------------------
BLOCKS = [
    ("BMB disjoint", "BMB VB0, VB10, 3", [("VB", 0, [1, 2, 3])], ("VB", 10, 3, [1, 2, 3])),
    ("BMB to M", "BMB VB0, MB0, 2", [("VB", 0, [9, 8])], ("MB", 0, 2, [9, 8])),
    # overlapping forward: plcrt copies element by element upwards
    # (docs/decisions.md), so the first element repeats
    ("BMB overlap forward", "BMB VB0, VB1, 4", [("VB", 0, [1, 2, 3, 4, 5, 6])],
     ("VB", 0, 6, [1, 1, 1, 1, 1, 6])),
    ("BMB overlap backward", "BMB VB1, VB0, 4", [("VB", 0, [1, 2, 3, 4, 5, 6])],
     ("VB", 0, 6, [2, 3, 4, 5, 5, 6])),
    ("BMB same place", "BMB VB0, VB0, 3", [("VB", 0, [1, 2, 3])], ("VB", 0, 3, [1, 2, 3])),
    ("BMW disjoint", "BMW VW0, VW100, 3", [("VW", 0, [-1, 2, 300])],
     ("VW", 100, 3, [-1, 2, 300])),
    ("BMW overlap forward", "BMW VW0, VW2, 3", [("VW", 0, [1, 2, 3, 4, 5])],
     ("VW", 0, 5, [1, 1, 1, 1, 5])),
    ("BMW odd overlap", "BMW VW0, VW1, 2", [("VB", 0, [1, 2, 3, 4, 5])],
     ("VB", 0, 5, [1, 1, 2, 2, 4])),                      # word by word
    ("BMW overlap backward", "BMW VW2, VW0, 3", [("VW", 0, [1, 2, 3, 4, 5])],
     ("VW", 0, 5, [2, 3, 4, 4, 5])),
    ("BMD", "BMD VD0, VD100, 2", [("VD", 0, [-5, 70000])], ("VD", 100, 2, [-5, 70000])),
    ("BMD overlap forward", "BMD VD0, VD4, 2", [("VD", 0, [7, 8, 9])],
     ("VD", 0, 3, [7, 7, 7])),
    ("BMB count from VB", "BMB VB0, VB10, VB50", [("VB", 0, [4, 5, 6]), ("VB", 50, [2])],
     ("VB", 10, 3, [4, 5, 0])),
    ("BMB through pointers", "MOVD &VB0, AC1\nMOVD &VB20, AC2\nBMB *AC1, *AC2, 3",
     [("VB", 0, [7, 8, 9])], ("VB", 20, 3, [7, 8, 9])),
    ("BMW from timers", "BMW T37, VW0, 2", [("T", 37, [11, 12])], ("VW", 0, 2, [11, 12])),
]


@pytest.mark.parametrize("label,body,preset,expected", BLOCKS, ids=[b[0] for b in BLOCKS])
def test_block_moves(label: str, body: str, preset: list, expected: tuple) -> None:
    """BMB/BMW/BMD copy N elements; overlapping ranges copy upwards one element at a time."""
    p = _load("LD SM0.0\n" + body)
    step = {"VB": 1, "MB": 1, "VW": 2, "VD": 4, "T": 1}
    for kind, start, values in preset:
        for i, v in enumerate(values):
            p[f"{kind}{start + i * step[kind]}"] = v
    p.scan()
    kind, start, count, values = expected
    assert [p[f"{kind}{start + i * step[kind]}"] for i in range(count)] == values


def test_block_move_past_the_area_end() -> None:
    """A constant block that does not fit is a compile error; a variable one stops the CPU."""
    with pytest.raises(PlcCompileError, match="runs past the end"):
        _load("LD SM0.0\nBMW VW10230, VW0, 10")
    p = _load("LD SM0.0\nBMB VB10230, VB0, VB0")
    p["VB0"] = 20
    with pytest.raises(PlcRuntimeError, match="past the end"):
        p.scan()
    assert p.mode == "STOP"


FILLS = [
    ("FILL const", "FILL +258, VW10, 3", {}, ("VW", 10, 4, [258, 258, 258, 0])),
    ("FILL negative", "FILL VW0, MW0, 2", {"VW0": -2}, ("MW", 0, 3, [-2, -2, 0])),
    ("FILL count from VB", "FILL +7, VW20, VB0", {"VB0": 2}, ("VW", 20, 3, [7, 7, 0])),
    ("FILL through a pointer", "MOVD &VB100, AC1\nFILL +9, *AC1, 3", {},
     ("VW", 100, 4, [9, 9, 9, 0])),
    ("FILL odd address", "FILL 16#0102, VW1, 2", {}, ("VB", 0, 6, [0, 1, 2, 1, 2, 0])),
]


@pytest.mark.parametrize("label,body,preset,expected", FILLS, ids=[f[0] for f in FILLS])
def test_fill(label: str, body: str, preset: dict, expected: tuple) -> None:
    """FILL writes IN to N consecutive words from OUT (N and OUT may be variable or indirect)."""
    p = _run(body, preset)
    kind, start, count, values = expected
    step = 1 if kind == "VB" else 2
    assert [p[f"{kind}{start + i * step}"] for i in range(count)] == values


def test_fill_past_the_area_end_stops_the_cpu() -> None:
    """A FILL whose variable count runs past the area end is a fatal run-time error."""
    p = _load("LD SM0.0\nFILL +1, VW10238, VB0")
    p["VB0"] = 2
    with pytest.raises(PlcRuntimeError, match="FILL runs past"):
        p.scan()
    assert p.mode == "STOP"


def test_fill_into_an_accumulator_is_a_compile_error() -> None:
    """FILL's OUT must be memory, not an accumulator."""
    with pytest.raises(PlcCompileError, match="accumulator"):
        _load("LD SM0.0\nFILL +1, AC1, 2")


# -- immediate byte transfers ----------------------------------------------------
class _PqProbe:
    """Records the physical outputs after OB1 ran (before the Q -> PQ copy)."""

    def __init__(self) -> None:
        self.seen: list[int] = []

    def step(self, plc: plcrt.Plc, t_from: int, t_to: int) -> None:
        self.seen.append(plc.mem.areas["PQ"][1])


def test_bir_reads_the_terminal_and_leaves_the_image() -> None:
    """BIR copies the physical input byte; the image IB (overwritten by the program) stays."""
    p = _load("LD SM0.0\nMOVB 0, IB0\nBIR IB0, VB0\nMOVB IB0, VB1")
    p.mem.areas["PI"][0] = 0x5A
    p.scan()
    assert (p["VB0"], p["VB1"]) == (0x5A, 0)


def test_biw_writes_terminal_and_image_at_once() -> None:
    """BIW writes the physical output byte and QB during the scan."""
    p = _load("LD SM0.0\nBIW VB1, QB1")
    probe = _PqProbe()
    p.devices.append(probe)
    p["VB1"] = 0x33
    p.scan()
    assert probe.seen == [0x33] and p["QB1"] == 0x33


@pytest.mark.parametrize("body", ["BIR VB0, VB1", "BIW VB0, VB1", "MOVB VB0, 3",
                                  "MOVW VW0, AIW0", "MOVB VB0, SMB5"])
def test_move_operand_misuse_is_a_compile_error(body: str) -> None:
    """BIR needs IB, BIW needs QB; constants, AIW and SMB0-29 cannot be written."""
    with pytest.raises(PlcCompileError):
        _load("LD SM0.0\n" + body)


@pytest.mark.parametrize("backend", ["python", "native"])
def test_writes_through_pointers_leave_the_read_only_sm_bytes(backend: str) -> None:
    """SMB0..SMB29 are read-only to the program: a write through a pointer
    keeps them (the writable bytes of a wider value are written) and says so
    once per instruction; SM0.0 stays on for the rest of the scan."""
    if backend == "native":
        pytest.importorskip("llvmlite")
    p = plcrt.load(ob1_text("LD SM0.0\nMOVD &SMB0, VD100\nMOVB 0, *VD100\n"
                            "MOVD &SMB28, VD104\nMOVD 16#11223344, *VD104\nMOVD &SMB30, VD108\n"
                            "MOVB 16#5A, *VD108",
                            "LD SM0.0\n= Q0.0\nLD SM0.0\nMOVB SMB0, VB0"), backend=backend)
    p.scan(2)
    sm = p.mem.areas["SM"]
    assert p["Q0.0"] == 1 and p["VB0"] & 1 == 1
    # SMB28/29 kept, SMB30/31 from the double word, then SMB30 by the byte
    assert bytes(sm[28:32]) == b"\x00\x00\x5a\x44"
    messages = [d.message for d in p.diagnostics if "read-only" in d.message]
    assert len(messages) == 2 and "SMB0" in messages[0] and "SMB28" in messages[1]
