"""Differential test: the compiled engine against the reference interpreter.

Hypothesis generates random *valid* STL programs (several networks, each
starting with a load) from the subset that ``tests/reference_interp.py``
models, plus random input sequences, initial V/M contents and scan times.
Both sides run scan by scan; after every scan every area both model must be
byte-for-byte identical.

Operands come from a small pool chosen to exercise aliasing: odd word
addresses (``VW1``), words and double words that overlap (``VW3`` / ``VD2``),
bits inside those words, T/C bits and current values, and SM flags.  Stack
depths reach 11, past the nine levels of the S7-200 logic stack.
"""

from __future__ import annotations

from dataclasses import dataclass

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import plcrt
from plcrt.isa.registry import lookup

from reference_interp import ReferencePlc, Unsupported  # tests/ is on sys.path (conftest)

#: Areas both sides model (and that OB1 can change or read).
COMPARED_AREAS = ("PI", "I", "Q", "PQ", "M", "V", "SM", "S", "TV", "TB", "CV", "CB")

#: The longest input sequence, in scans.
MAX_SCANS = 60

# -- operand pools -----------------------------------------------------------

V_BYTES = 12  #: VB0..VB11 are seeded with random initial values
M_BYTES = 4   #: MB0..MB3 likewise

TIMERS = ("T37", "T38", "T39", "T40")
COUNTERS = ("C0", "C1", "C2", "C3")

BIT_WRITE = (
    [f"Q0.{b}" for b in range(8)] + ["Q1.0", "Q1.7", "I0.6", "I1.3"]
    + [f"M{y}.{b}" for y in (0, 1, 3) for b in (0, 3, 7)]
    + [f"V{y}.{b}" for y in range(V_BYTES) for b in (0, 1, 6, 7)]
    + ["S0.0", "S0.5", "S1.2"]
)
BIT_READ = (
    BIT_WRITE
    + [f"I0.{b}" for b in range(8)] + [f"I1.{b}" for b in (0, 1, 7)]
    + ["SM0.0", "SM0.1", "SM0.4", "SM0.5", "SM0.6", "SM1.0", "SM1.1", "SM1.2", "SM1.3"]
    + list(TIMERS) + list(COUNTERS)
)

BYTE_WRITE = ("QB0", "QB1", "MB0", "MB3") + tuple(f"VB{i}" for i in range(V_BYTES))
BYTE_READ = BYTE_WRITE + ("IB0", "IB1", "SMB0", "SMB1")
BYTE_CONST = ("0", "1", "2", "127", "128", "254", "255", "16#80")

#: T37 / C1 in word context are the current values; programs may write them.
WORD_WRITE = ("QW0", "MW0", "MW1", "MW2", "VW0", "VW1", "VW2", "VW3", "VW5", "VW8", "VW10",
              "T37", "C1")
WORD_READ = WORD_WRITE + ("IW0", "SMW22", "T38", "T39", "T40", "C0", "C2", "C3")
WORD_CONST = ("0", "1", "-1", "+2", "3", "+100", "255", "256", "32767", "-32767",
              "-32768", "16#FFFF", "16#8000", "65535", "-2")

DWORD_WRITE = ("QD0", "MD0", "VD0", "VD1", "VD2", "VD3", "VD4", "VD6", "VD8")
DWORD_READ = DWORD_WRITE + ("ID0",)
DWORD_CONST = ("0", "1", "-1", "+2", "32767", "32768", "-32768", "65536", "+100000",
               "2147483647", "-2147483648", "-2147483647", "16#FFFFFFFF", "16#80000000",
               "16#7FFF0000")

#: Strings start in the seeded bytes, so their length bytes are random (255,
#: out of range, included); constants cover quoting and the number forms.
STRING_AT = ("VB0", "VB3", "VB6", "VB9")
#: Compared strings: their length bytes are written only by string
#: instructions, which write valid strings, and no other string reaches them
#: (a string at VB20 ends by VB275); a compare of an invalid string would stop
#: the CPU.  IN1 of a compare may be a constant.
STRING_COMPARED = ("VB300", "VB600")
STRING_READ = STRING_AT + ("VB300", '"AB"', '""', '"  -12,5x"', '"A""1b2"', '"+7.25"')
STRING_WRITE = STRING_AT + ("VB20",) + STRING_COMPARED
STRING_COMPARE_IN1 = STRING_COMPARED + ('"AB"', '""', '"A""1b2"')
STRING_INDEX = ("0", "1", "2", "3", "9", "VB1", "VB4", "VB7")
STRING_FORMATS = ("0", "3", "5", "6", "16#0B", "16#13", "16#30", "16#61", "16#A6", "16#F5",
                  "VB2", "VB5")

#: Width letter -> (read pool, write pool, constants).
POOLS = {
    "B": (BYTE_READ, BYTE_WRITE, BYTE_CONST),
    "W": (WORD_READ, WORD_WRITE, WORD_CONST),
    "D": (DWORD_READ, DWORD_WRITE, DWORD_CONST),
}

RELATIONS = ("=", "<>", "<", "<=", ">", ">=")
MATH_OPS = {"+I": "W", "-I": "W", "*I": "W", "/I": "W", "+D": "D", "-D": "D", "*D": "D",
            "/D": "D"}
INC_DEC_OPS = {"INCB": "B", "DECB": "B", "INCW": "W", "DECW": "W", "INCD": "D", "DECD": "D"}
#: Word logic only where the compiled engine has it.
WORD_LOGIC_OPS = tuple(m for m in ("ANDW", "ORW", "XORW") if lookup(m) is not None)

SCAN_MS = (10, 20, 50, 100, 130, 1000, 7000, 60000)


# -- strategies --------------------------------------------------------------
#
# Generation dominates the run time, so every choice below is one draw from a
# precomputed list where possible (fewer, flatter draws also shrink better).

#: Width letter -> operands an input may be (addresses and constants).
VALUE_INPUTS = {w: reads + consts for w, (reads, _writes, consts) in POOLS.items()}
VALUE_INPUTS["S"] = STRING_COMPARE_IN1

BIT_LOADS = tuple(f"{m} {b}" for m in ("LD", "LDN") for b in BIT_READ)
BIT_COMBINES = tuple(f"{m} {b}" for m in ("A", "AN", "O", "ON") for b in BIT_READ)
BIT_OUTPUTS = tuple(f"= {b}" for b in BIT_WRITE)
SET_RESET_HEADS = (tuple(f"{m} {b}" for m in ("S", "R") for b in BIT_WRITE)
                   + tuple(f"R {tc}" for tc in TIMERS + COUNTERS))

#: (mnemonic, width) of the compares, per prefix.
COMPARES = {prefix: tuple((f"{prefix}{w}{rel}", w) for w in "BWD" for rel in RELATIONS)
            + tuple((f"{prefix}S{rel}", "S") for rel in ("=", "<>"))
            for prefix in ("LD", "A", "O")}
COMPARES["A/O"] = COMPARES["A"] + COMPARES["O"]

#: Boxes: (mnemonic, width, has an input operand).  OUT is always writable.
BOXES = (
    tuple((f"MOV{w}", w, True) for w in "BWD")
    + tuple((m, w, True) for m, w in MATH_OPS.items())
    + tuple((m, w, False) for m, w in INC_DEC_OPS.items())
    + tuple((m, "W", True) for m in WORD_LOGIC_OPS)
)

PRESETS = ("0", "1", "2", "3", "+5", "10", "-1", "32767", "VW0", "VW1", "MW1", "C0", "T38")


def _choice(options: tuple) -> st.SearchStrategy:
    """``st.sampled_from`` built once per option tuple (building strategies is
    costly: every new one is validated and labelled at its first draw)."""
    strategy = _CHOICES.get(options)
    if strategy is None:
        strategy = _CHOICES[options] = st.sampled_from(options)
    return strategy


_CHOICES: dict[tuple, st.SearchStrategy] = {}


@st.composite
def _compare_insn(draw: st.DrawFn, prefix: str) -> str:
    mnemonic, width = draw(_choice(COMPARES[prefix]))
    inputs = _choice(VALUE_INPUTS[width])
    second = _choice(STRING_COMPARED) if width == "S" else inputs
    return f"{mnemonic} {draw(inputs)}, {draw(second)}"


COMPARE_INSN = {prefix: _compare_insn(prefix) for prefix in COMPARES}


@st.composite
def _box_insn(draw: st.DrawFn) -> str:
    """A box: runs when the top is 1, leaves the stack alone."""
    mnemonic, width, has_input = draw(_choice(BOXES))
    out = draw(_choice(POOLS[width][1]))
    if not has_input:
        return f"{mnemonic} {out}"
    return f"{mnemonic} {draw(_choice(VALUE_INPUTS[width]))}, {out}"


BOX_INSN = _box_insn()

#: String boxes: mnemonic -> operand pools in STL order.
STRING_BOXES = {
    "SLEN": (STRING_READ, BYTE_WRITE),
    "SCPY": (STRING_READ, STRING_WRITE),
    "SCAT": (STRING_READ, STRING_WRITE),
    "SSCPY": (STRING_READ, STRING_INDEX, STRING_INDEX, STRING_WRITE),
    "SFND": (STRING_READ, STRING_READ, BYTE_WRITE),
    "CFND": (STRING_READ, STRING_READ, BYTE_WRITE),
    "ITS": (VALUE_INPUTS["W"], STRING_WRITE, STRING_FORMATS),
    "DTS": (VALUE_INPUTS["D"], STRING_WRITE, STRING_FORMATS),
    "RTS": (("VD0", "VD4", "VD8", "MD0"), STRING_WRITE, STRING_FORMATS),
    "STI": (STRING_READ, STRING_INDEX, WORD_WRITE),
    "STD": (STRING_READ, STRING_INDEX, DWORD_WRITE),
    "STR": (STRING_READ, STRING_INDEX, DWORD_WRITE),
}


@st.composite
def _string_insn(draw: st.DrawFn) -> str:
    mnemonic = draw(_choice(tuple(STRING_BOXES)))
    return f"{mnemonic} " + ", ".join(draw(_choice(pool)) for pool in STRING_BOXES[mnemonic])


STRING_INSN = _string_insn()


# Table and ASCII boxes (where the compiled engine has them).  A table at
# VW20 starts empty with TL 0 (a MOVW sets TL); the one at VW0 lies in the
# seeded bytes, so its entry count is mostly out of range (error 0091).
TABLE_SETUP = tuple(f"MOVW {c}, VW20" for c in ("0", "1", "2", "3", "5", "101"))
FIND_OPS = ("FND=", "FND<>", "FND<", "FND>")
ITA_FORMATS = ("0", "3", "16#0B", "5", "6", "16#13", "VB1")
RTA_FORMATS = ("16#61", "16#A3", "16#30", "16#20", "16#F5", "16#86", "16#4D", "VB1")
HEX_LENGTHS = ("0", "1", "3", "8", "12", "VB11")
DATA_OPS = tuple(m for m in ("ATT", "FIFO", "LIFO", *FIND_OPS, "ITA", "DTA", "RTA", "ATH", "HTA")
                 if lookup(m) is not None)


@st.composite
def _data_insn(draw: st.DrawFn) -> str:
    """One table or ASCII box (inputs from the word/dword pools)."""
    m = draw(_choice(DATA_OPS + ("setup",)))
    word_in = _choice(VALUE_INPUTS["W"])
    table = draw(_choice(("VW20", "VW20", "VW0")))
    if m == "setup":
        return draw(_choice(TABLE_SETUP))
    if m == "ATT":
        return f"ATT {draw(word_in)}, {table}"
    if m in ("FIFO", "LIFO"):
        return f"{m} {table}, {draw(_choice(WORD_WRITE))}"
    if m in FIND_OPS:
        count = "VW22" if table == "VW20" else "VW2"
        return f"{m} {count}, {draw(word_in)}, {draw(_choice(WORD_WRITE))}"
    if m == "ITA":
        return f"ITA {draw(word_in)}, VB30, {draw(_choice(ITA_FORMATS))}"
    if m == "DTA":
        return f"DTA {draw(_choice(VALUE_INPUTS['D']))}, VB40, {draw(_choice(ITA_FORMATS))}"
    if m == "RTA":
        return f"RTA {draw(_choice(DWORD_READ))}, VB56, {draw(_choice(RTA_FORMATS))}"
    return f"{m} VB0, VB80, {draw(_choice(HEX_LENGTHS))}"


DATA_INSN = _data_insn()
LOAD_INSN = st.one_of(_choice(BIT_LOADS), COMPARE_INSN["LD"])
DEEP_PUSH = st.one_of(_choice(BIT_LOADS), st.just("LPS"))
DEEP_COUNT = _choice((0, 0, 0, 4, 6, 8, 9, 10))
NETWORK_LENGTH = st.integers(1, 12)
NETWORK_COUNT = st.integers(1, 5)
#: S/R counts: timers / counters from the pool on, bits up to 100 (every pool
#: start bit leaves room for 100 bits in its area).
RANGE_COUNT = {"T": st.integers(1, 3), "C": st.integers(1, 3),
               "bits": st.one_of(st.integers(1, 12), st.sampled_from((16, 33, 100)))}

#: Instruction kinds and how they change the static stack depth.
PUSHES = {"load": 1, "load_cmp": 1, "lps": 1, "ald/old": -1, "lpp": -1, "ctu": -1}
ALWAYS = ("load", "load_cmp", "combine", "combine_cmp", "not", "edge", "lps", "out", "out",
          "setreset", "box", "box", "string") + (("data",) if DATA_OPS else ())
WITH_TWO = ("ald/old", "ald/old", "lrd", "lpp")


def draw_network(draw: st.DrawFn, counters: list[str]) -> list[str]:
    """One network starting with a load.

    ``depth`` is the compiler's static stack depth (at most nine, as the
    bottom level is lost on overflow); pops are only drawn when it allows.
    ``counters`` holds the counter numbers still free: each is used by at
    most one box, as the manual requires.
    """
    lines = [draw(LOAD_INSN)]
    depth = 1
    # a "deep" network first pushes many levels, to overflow the stack
    for _ in range(draw(DEEP_COUNT)):
        lines.append(draw(DEEP_PUSH))
        depth = min(depth + 1, 9)
    for _ in range(draw(NETWORK_LENGTH)):
        kinds: tuple[str, ...] = ALWAYS
        if depth >= 2:
            kinds += WITH_TWO + (("ctu",) if counters else ())
        kinds += ("ton",)
        kind = draw(_choice(kinds))
        if kind == "load":
            lines.append(draw(_choice(BIT_LOADS)))
        elif kind == "load_cmp":
            lines.append(draw(COMPARE_INSN["LD"]))
        elif kind == "combine":
            lines.append(draw(_choice(BIT_COMBINES)))
        elif kind == "combine_cmp":
            lines.append(draw(COMPARE_INSN["A/O"]))
        elif kind == "not":
            lines.append("NOT")
        elif kind == "edge":
            lines.append(draw(_choice(("EU", "ED"))))
        elif kind == "lps":
            lines.append("LPS")
        elif kind == "out":
            lines.append(draw(_choice(BIT_OUTPUTS)))
        elif kind == "setreset":
            head = draw(_choice(SET_RESET_HEADS))
            count = RANGE_COUNT.get(head[2], RANGE_COUNT["bits"])
            lines.append(f"{head}, {draw(count)}")
        elif kind == "box":
            lines.append(draw(BOX_INSN))
        elif kind == "string":
            lines.append(draw(STRING_INSN))
        elif kind == "data":
            lines.append(draw(DATA_INSN))
        elif kind == "ald/old":
            lines.append(draw(_choice(("ALD", "OLD"))))
        elif kind == "lrd":
            lines.append("LRD")
        elif kind == "lpp":
            lines.append("LPP")
        elif kind == "ctu":
            c = draw(_choice(tuple(counters)))
            counters.remove(c)
            lines.append(f"CTU {c}, {draw(_choice(PRESETS))}")
        elif kind == "ton":
            # a timer may run twice per scan: a 100 ms timer then gains time
            # (System Manual, digest section 3.4), so numbers can repeat
            t = draw(_choice(TIMERS))
            lines.append(f"TON {t}, {draw(_choice(PRESETS))}")
        depth = min(depth + PUSHES.get(kind, 0), 9)
    return lines


def render(networks: list[list[str]]) -> str:
    """Program text in Micro/WIN export form."""
    out = ["ORGANIZATION_BLOCK MAIN:OB1", "TITLE=PROGRAM COMMENTS", "BEGIN"]
    for i, lines in enumerate(networks, 1):
        out.append(f"Network {i} ")
        out.extend(lines)
    out.append("END_ORGANIZATION_BLOCK")
    return "\n".join(out) + "\n"


@st.composite
def programs(draw: st.DrawFn) -> str:
    counters = list(COUNTERS)
    count = draw(NETWORK_COUNT)
    return render([draw_network(draw, counters) for _ in range(count)])


@dataclass(frozen=True)
class Case:
    """One differential run: program, stimulus and initial memory."""

    program: str
    #: (IB0, IB1, number of scans) segments; inputs hold for that many scans
    inputs: tuple[tuple[int, int, int], ...]
    scan_ms: int = 10
    initial_v: bytes = bytes(V_BYTES)
    initial_m: bytes = bytes(M_BYTES)


SEGMENTS = st.lists(
    st.tuples(st.integers(0, 255), st.integers(0, 255), st.integers(1, 12)),
    min_size=1, max_size=8)
INITIAL_MEMORY = st.one_of(
    st.binary(min_size=V_BYTES + M_BYTES, max_size=V_BYTES + M_BYTES),
    # words of edge values: 16#7FFF, 16#8000, 16#FFFF, 16#0001, 16#7F80
    st.sampled_from((b"\x7f\xff", b"\x80\x00", b"\xff\xff", b"\x00\x01",
                     b"\x7f\x80")).map(lambda w: w * ((V_BYTES + M_BYTES) // 2)),
)


@st.composite
def cases(draw: st.DrawFn) -> Case:
    program = draw(programs())
    segments = draw(SEGMENTS)
    initial = draw(INITIAL_MEMORY)
    return Case(program, tuple(segments), draw(_choice(SCAN_MS)),
                initial[:V_BYTES], initial[V_BYTES:])


# -- the differential run ----------------------------------------------------

def _describe_difference(area: str, got: bytes, want: bytes) -> str:
    offsets = [i for i, (g, w) in enumerate(zip(got, want)) if g != w]
    shown = ", ".join(f"{area}B{i}: engine {got[i]:#04x} reference {want[i]:#04x}"
                      for i in offsets[:6])
    return shown + (" ..." if len(offsets) > 6 else "")


def run_side_by_side(case: Case, instrument: bool = False, backend: str = "python") -> None:
    """Run both sides over the case; assert identical memory after each scan."""
    engine = plcrt.load(case.program, scan_ms=case.scan_ms, instrument=instrument,
                        backend=backend)
    reference = ReferencePlc(case.program, scan_ms=case.scan_ms)
    for mem in (engine.mem.areas, reference.mem):
        mem["V"][:V_BYTES] = case.initial_v
        mem["M"][:M_BYTES] = case.initial_m
    scan = 0
    for ib0, ib1, repeat in case.inputs:
        for _ in range(repeat):
            if scan >= MAX_SCANS:
                return
            for mem in (engine.mem.areas, reference.mem):
                mem["PI"][0] = ib0
                mem["PI"][1] = ib1
            engine.scan()
            reference.scan()
            scan += 1
            for area in COMPARED_AREAS:
                got, want = bytes(engine.mem.areas[area]), bytes(reference.mem[area])
                assert got == want, (
                    f"scan {scan} (t = {(scan - 1) * case.scan_ms} ms): "
                    f"{_describe_difference(area, got, want)}\n{case.program}")


# -- fixed regression examples ------------------------------------------------

def _prog(*networks: str) -> str:
    return render([n.strip().splitlines() for n in networks])


#: Ten pushes: the first level (a 0) is lost, eight ALDs combine levels 2..10.
STACK_OVERFLOW = _prog("""
LDN SM0.0
LD SM0.0
LD SM0.0
LD SM0.0
LD SM0.0
LD SM0.0
LD SM0.0
LD SM0.0
LD SM0.0
LD SM0.0
ALD
ALD
ALD
ALD
ALD
ALD
ALD
ALD
= Q0.0
""")

#: Overflow by LPS, then LRD / LPP reach the copied levels.
STACK_LPS_OVERFLOW = _prog("""
LD I0.0
LPS
LPS
LPS
LPS
LPS
LPS
LPS
LPS
LPS
LPS
AN I0.1
LRD
= Q0.1
LPP
= Q0.2
""")

#: Overflowing math leaves OUT alone; INC wraps; odd/overlapping addresses.
MATH_EDGES = _prog("""
LD SM0.0
MOVW +32767, VW1
+I +1, VW1
= Q0.0
MOVD -2147483648, VD2
-D +1, VD2
INCW VW1
DECB VB7
*I -32768, VW3
/I 0, VW3
/I -1, VW8
""")

#: Counter (CU second level, R top) and a 100 ms TON reading T/C values.
TIMER_COUNTER = _prog("""
LD I0.0
LD I0.1
CTU C0, +3
""", """
LD SM0.0
TON T37, +2
LDW>= T37, C0
= Q0.5
""", """
LD C0
EU
S V0.0, 12
""")


#: Tables filled, emptied and searched; every ASCII conversion and its errors.
DATA_EDGES = _prog("""
LD SM0.0
MOVW 3, VW20
ATT VW1, VW20
ATT -7, VW20
ATT VW3, VW20
ATT +9, VW20
= Q0.1
FND> VW22, -8, VW8
FIFO VW20, VW10
LIFO VW20, MW0
ATT VW8, VW0
ITA VW1, VB30, 16#0B
DTA VD2, VB40, 3
RTA VD4, VB56, 16#A3
RTA VD6, VB56, 16#41
ATH VB0, VB80, 5
HTA VB0, VB80, 7
""", """
LD SM0.0
FIFO VW20, VW10
LIFO VW20, VW10
LIFO VW20, VW10
FND= VW2, 0, VW5
""")


#: cases every backend runs besides the drawn ones (each once found a bug
#: or pins an edge: data instructions, stack overflow, math limits, timers
#: and counters, the longest timer at the longest scan)
REGRESSIONS = (
    Case(DATA_EDGES, ((0, 0, 3),), initial_v=b"3A\x00\x05B\xf6\xe6\x66\x01\x00\x00\x02"),
    Case(STACK_OVERFLOW, ((0, 0, 2),)),
    Case(STACK_LPS_OVERFLOW, ((1, 0, 2), (3, 0, 2), (0, 0, 1))),
    Case(MATH_EDGES, ((0, 0, 3),), initial_v=bytes([0x80, 0, 0, 0x80, 0, 0, 0, 0,
                                                    0x80, 0, 0, 0])),
    Case(TIMER_COUNTER, ((1, 0, 3), (0, 0, 2), (1, 0, 4), (3, 0, 1), (1, 0, 12)), scan_ms=50),
    Case(_prog("LD I0.0\nTON T37, 32767\nLDW= T37, 32767\n= Q0.0"), ((1, 0, 57),),
         scan_ms=60000),
)


def with_regressions(test):
    """The test, with every case of :data:`REGRESSIONS` as an example."""
    for case in reversed(REGRESSIONS):
        test = example(case=case)(test)
    return test


@settings(max_examples=400, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(case=cases())
@with_regressions
def test_compiled_engine_matches_reference(case: Case) -> None:
    run_side_by_side(case)


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(case=cases())
@example(Case(STACK_OVERFLOW, ((0, 0, 2),)))
@example(Case(STACK_LPS_OVERFLOW, ((1, 0, 2), (3, 0, 2), (0, 0, 1))))
def test_probed_engine_matches_reference(case: Case) -> None:
    """The coverage probes (contacts split into load + ALD/OLD, output and
    network marks) never change what a program does, stack overflows included."""
    run_side_by_side(case, instrument=True)


@settings(max_examples=300, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(case=cases())
@with_regressions
def test_native_engine_matches_reference(case: Case) -> None:
    """The native backend (machine code for the pieces it lowers, Python for
    the others, in one scan) computes what the reference does, scan by scan."""
    pytest.importorskip("llvmlite")
    run_side_by_side(case, backend="native")


# Regression: an early version of the contact-run folding (Gen.combine) turned
# ``LDN x`` / ``LDx=`` followed by ``A``/``AN`` into ``x ^ 1 & y`` and
# ``1 if c else 0 & y``, which Python groups as ``x ^ (1 & y)`` and
# ``1 if c else (0 & y)``.
@pytest.mark.parametrize("body, inputs", [
    # I0.0 = 1: LDN gives 0, so Q0.0 = 0 AND I0.1 = 0 (the engine gave 1)
    ("LDN I0.0\nA I0.1\n= Q0.0", ((1, 0, 1),)),
    # VW0 = 0: the compare gives 1, I0.1 = 0, so Q0.0 = 0 (the engine gave 1)
    ("LDW= VW0, 0\nA I0.1\n= Q0.0", ((0, 0, 1),)),
    ("LDB<> VB1, 1\nAN I0.1\n= Q0.0", ((2, 0, 1),)),
    # fused runs: (I0.0 OR NOT I0.1) AND I0.2, and a pending run folded by ALD / OLD
    ("LD I0.0\nON I0.1\nA I0.2\n= Q0.0", ((3, 0, 1), (4, 0, 1), (6, 0, 1))),
    ("LD I0.0\nLDN I0.1\nA I0.2\nO I0.3\nALD\nLDW= VW0, 0\nOLD\n= Q0.0",
     ((1, 0, 1), (5, 0, 1), (9, 0, 1), (0, 0, 1))),
])
def test_fused_contact_runs(body: str, inputs: tuple) -> None:
    run_side_by_side(Case(_prog(body), inputs))


# -- the oracle against hand-derived expectations ------------------------------

def test_reference_stack_overflow_loses_bottom() -> None:
    """The 0 pushed first is lost by the tenth push, so Q0.0 = 1."""
    ref = ReferencePlc(STACK_OVERFLOW)
    ref.scan()
    assert ref.mem["Q"][0] & 1 == 1


def test_lost_level_is_never_read() -> None:
    """After ten pushes nine levels remain: a ninth ALD would read the lost
    level (the manual: its value is unknown).  Both sides refuse it, which
    is why random programs never pop below the static depth."""
    text = _prog("LD I0.0\n" * 10 + "ALD\n" * 9 + "= Q0.0")
    with pytest.raises(plcrt.PlcCompileError, match="needs 2 values"):
        plcrt.load(text)
    with pytest.raises(Unsupported):
        ReferencePlc(text).scan()


def test_reference_math_edges() -> None:
    """+I overflow keeps OUT and sets SM1.1; INCW wraps (math_int.py)."""
    ref = ReferencePlc(_prog("LD SM0.0\nMOVW +32767, VW1\n+I +1, VW1\n= Q0.0"))
    ref.scan()
    assert int.from_bytes(ref.mem["V"][1:3], "big", signed=True) == 32767
    assert ref.mem["SM"][1] & 0b111 == 0b010
    ref = ReferencePlc(_prog("LD SM0.0\nMOVW +32767, VW1\nINCW VW1"))
    ref.scan()
    assert int.from_bytes(ref.mem["V"][1:3], "big", signed=True) == -32768
    assert ref.mem["SM"][1] & 0b111 == 0b110


def test_reference_ton_100ms() -> None:
    """TON T37, 2 at 50 ms scans: CV 0, 0, 1, 1, 2 -> the bit at the 5th scan."""
    ref = ReferencePlc(_prog("LD SM0.0\nTON T37, 2"), scan_ms=50)
    values = []
    for _ in range(5):
        ref.scan()
        values.append((int.from_bytes(ref.mem["TV"][74:76], "big"), ref.mem["TB"][4] >> 5 & 1))
    assert values == [(0, 0), (0, 0), (1, 0), (1, 0), (2, 1)]
