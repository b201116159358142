"""The native backend (plcrt.compiler.native): its table, its fallbacks, its
disk cache, and the PLC features that must keep working on it.

Each lowered instruction has a row here: a small program that drives it
through its edge values, run on both backends; the pieces must be machine
code (nothing left in Python) and the memory equal after every scan.  The
random programs of tests/engine/test_differential.py and test_backends.py
cover the combinations.
"""

from __future__ import annotations

import pytest

import plcrt
from plcrt.compiler.cache import programs as program_cache
from plcrt.errors import PlcConfigError
from plcrt.isa.registry import lookup

pytest.importorskip("llvmlite")

from plcrt.compiler.native.lower import LOWER  # noqa: E402

AREAS = ("I", "Q", "M", "V", "SM", "S", "TV", "TB", "CV", "CB", "AC")


def _ob1(*networks: str) -> str:
    body = "".join(f"Network {i}\n{n.strip()}\n" for i, n in enumerate(networks, 1))
    return f"ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\n{body}END_ORGANIZATION_BLOCK\n"


def _pair(text: str, **kw):
    return plcrt.load(text, backend="python", **kw), plcrt.load(text, backend="native", **kw)


def _same(py, nat, where: str) -> None:
    for area in AREAS:
        assert bytes(nat.mem.areas[area]) == bytes(py.mem.areas[area]), f"{where}: {area}"


def _run_both(text: str, scans: int = 6, inputs=(0x00, 0x01, 0x03, 0x02, 0xFF, 0x80),
              v: bytes = b"", **kw):
    py, nat = _pair(text, **kw)
    for plc in (py, nat):
        plc.mem.areas["V"][:len(v)] = v
    for k in range(scans):
        for plc in (py, nat):
            plc.mem.areas["PI"][0] = inputs[k % len(inputs)]
            plc.scan()
        _same(py, nat, f"scan {k + 1}")
    return py, nat


# V memory with edge values: 16#7FFF, 16#8000, 16#FFFF, 0, 16#7FFFFFFF, 16#80000000
EDGE_V = bytes.fromhex("7fff8000ffff0000" "7fffffff80000000" "00ff0180")

#: mnemonic -> a network using it (inputs I0.0/I0.1 change from scan to scan)
ROWS = {
    "LD": "LD I0.0\n= Q0.0", "LDN": "LDN I0.0\n= Q0.0",
    "A": "LD I0.0\nA I0.1\n= Q0.0", "AN": "LD I0.0\nAN I0.1\n= Q0.0",
    "O": "LD I0.0\nO I0.1\n= Q0.0", "ON": "LD I0.0\nON I0.1\n= Q0.0",
    "NOT": "LD I0.0\nNOT\n= Q0.1",
    "ALD": "LD I0.0\nLD I0.1\nO M0.0\nALD\n= Q0.0",
    "OLD": "LD I0.0\nA I0.1\nLDN I0.0\nA M0.1\nOLD\n= Q0.0",
    "LPS": "LD I0.0\nLPS\nA I0.1\n= Q0.0\nLPP\n= Q0.1",
    "LRD": "LD I0.0\nLPS\nA I0.1\n= Q0.0\nLRD\nAN I0.1\n= Q0.1\nLPP\n= Q0.2",
    "LPP": "LD I0.0\nLPS\nAN I0.1\n= Q0.3\nLPP\nA I0.7\n= Q0.4",
    "LDS": "LD I0.0\nLD I0.1\nLDS 1\n= Q0.0\nLPP\n= Q0.1",
    "NOP": "LD I0.0\nNOP 0\n= Q0.0",
    "=": "LD I0.1\n= V30.7\n= M1.3\n= S0.1",
    "S": "LD I0.0\nS M0.5, 12\nS V31.0, 1",
    "R": "LD I0.1\nR M0.5, 5\nLD I0.7\nR V31.0, 1\nR M0.0, 16\n"
         "LD I0.0\nTON T37, +50\nTON T38, +2\nLD I0.1\nR T37, 2",
    "MOVB": "LD I0.0\nMOVB VB1, VB20\nMOVB 16#FE, QB1\nMOVB VB2, AC0\nMOVB 'A', VB21",
    "MOVW": "LD I0.0\nMOVW VW1, VW22\nMOVW -2, VW24\nMOVW VW0, T37\nMOVW AC0, C3",
    "MOVD": "LD I0.1\nMOVD VD8, VD26\nMOVD &VB10, VD30\nMOVD VD12, AC1\nMOVD AC1, VD34\n"
            "MOVD 'AB', VD42\nMOVR 1.5, VD38",
    "+I": "LD SM0.0\n+I VW0, VW22\n+I VW2, VW24\n+I +1, VW0",
    "-I": "LD SM0.0\n-I +1, VW2\n-I VW4, VW26",
    "*I": "LD I0.0\n*I +3, VW0\n*I VW2, VW28\n*I -1, VW2",
    "+D": "LD SM0.0\n+D VD8, VD20\n+D +1, VD8",
    "-D": "LD SM0.0\n-D +1, VD12\n-D VD20, VD24",
    "*D": "LD I0.0\n*D +2, VD8\n*D -1, VD12",
    "INCB": "LD SM0.0\nINCB VB17\nINCB VB16", "DECB": "LD SM0.0\nDECB VB6\nDECB VB16",
    "INCW": "LD SM0.0\nINCW VW0\nINCW VW4", "DECW": "LD SM0.0\nDECW VW2\nDECW VW6",
    "INCD": "LD SM0.0\nINCD VD8", "DECD": "LD SM0.0\nDECD VD12\nDECD VD4",
    "EU": "LD I0.0\nEU\n= Q0.0\nLD I0.1\nA I0.0\nEU\nINCW VW30",
    "ED": "LD I0.0\nED\n= Q0.0\nLDN I0.1\nED\nINCW VW30",
    "MOVR": "LD I0.0\nMOVR VD8, VD20\nMOVR 1.5, VD24\nMOVR -3.4e38, AC1\nMOVR 7, VD28",
    "TONR": "LD I0.0\nTONR T5, +4\nLD T5\n= Q0.0\nLD I0.1\nTONR T6, VW2\nLD Q0.7\nR T5, 1\n"
            "LD T5\n= Q0.7",
    "TOF": "LD I0.0\nTOF T40, +3\nLD T40\n= Q0.0\nLDN I0.1\nTOF T41, +1\nLD I0.7\nR T40, 1\n"
           "LD SM0.1\nTOF T42, +2\nLD T42\n= Q0.1",
    "TON": "LD I0.0\nTON T37, +3\nLD T37\n= Q0.0\nLDN I0.0\nTON T38, VW2\n"
           "LD I0.1\nTON T101, +1",
}
for _w, _a, _b in (("B", "VB1", "VB17"), ("W", "VW2", "VW4"), ("D", "VD8", "VD12")):
    for _stem in ("AND", "OR", "XOR"):
        ROWS[f"{_stem}{_w}"] = (f"LD I0.0\n{_stem}{_w} {_a}, {_b}\n{_stem}{_w} 16#0F, {_a}\n"
                                f"{_stem}{_w} {_b}, AC0")
    ROWS[f"INV{_w}"] = f"LD I0.0\nINV{_w} {_a}\nINV{_w} AC1"
for _w, _a, _b in (("B", "VB18", "VB19"), ("W", "VW2", "VW18"), ("D", "VD8", "VD16")):
    for _stem in ("SL", "SR", "RL", "RR"):
        # counts 0, 1, width - 1, width, past the width, and 255, on
        # patterns whose lowest and highest bits differ
        ROWS[f"{_stem}{_w}"] = "LD I0.0\n" + "\n".join(
            f"{_stem}{_w} {x}, {k}" for x in (_a, _b) for k in (0, 1, 7, 8, 16, 31, 32, 40, 255))
ROWS["ITB"] = ("LD I0.0\nITB VW0, VB20\nITB +255, VB21\nITB VW6, VB22\nITB -1, VB23\n"
               "ITB +256, VB24")
ROWS["DTI"] = ("LD I0.0\nDTI VD8, VW20\nDTI VD12, VW22\nDTI +32767, VW24\nDTI VD4, VW26\n"
               "DTI +32768, VW28\nDTI -32769, VW30\nDTI -32768, VW32")
ROWS["BTI"] = "LD I0.0\nBTI VB17, VW20\nBTI VB16, AC0"
ROWS["ITD"] = "LD I0.0\nITD VW2, VD20\nITD VW0, VD24\nITD AC0, AC1"
for _p in ("LD", "A", "O"):
    for _w, _a, _b in (("B", "VB1", "VB2"), ("W", "VW0", "VW2"), ("D", "VD8", "VD12")):
        for _r in ("=", "<>", "<", "<=", ">", ">="):
            head = "LD I0.0\n" if _p != "LD" else ""
            ROWS[f"{_p}{_w}{_r}"] = (f"{head}{_p}{_w}{_r} {_a}, {_b}\n= Q0.0\n"
                                     f"{'LD I0.1' if _p != 'LD' else ''}\n"
                                     f"{_p}{_w}{_r} {_b}, {_a}\n= Q0.1\n").replace("\n\n", "\n")


def test_every_lowering_is_an_instruction_with_a_row() -> None:
    """The native table lowers registered instructions only, and each has a
    row; besides them only the probes of an instrumented program (``@``)."""
    insns = [m for m in LOWER if not m.startswith("@")]
    for mnemonic in insns:
        assert lookup(mnemonic) is not None, mnemonic
    assert sorted(insns) == sorted(ROWS)
    assert sorted(set(LOWER) - set(insns)) == ["@CON", "@NET", "@OUT"]


@pytest.mark.parametrize("mnemonic", sorted(ROWS))
def test_lowered_instruction_matches_python(mnemonic: str) -> None:
    """Each lowered instruction runs as machine code and writes what the
    Python backend writes, scan by scan, over edge values (overflow, wrap,
    sign, SM1 flags, timers at 100 ms ticks)."""
    text = _ob1(ROWS[mnemonic])
    py, nat = _run_both(text, scans=40, v=EDGE_V, scan_ms=30)
    info = nat.backend
    assert info["python"] == [] and info["pieces"] == 1, info


def test_pieces_outside_the_table_fall_back_per_network_with_a_reason() -> None:
    text = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\n= Q0.0\n"
            "Network 2\nLD I0.0\nLD I0.1\nCTU C3, +4\nNetwork 3\nLD I0.0\nPLS 0\n"
            "Network 4\nLD I0.1\nTON T33, +5\nNetwork 5\nLD SM0.0\nCALL SBR_0, VW0\n"
            "Network 6\nLD I0.1\n= Q0.2\nEND_ORGANIZATION_BLOCK\n"
            "SUBROUTINE_BLOCK SBR_0:SBR0\nVAR_INPUT\nx:INT;\nEND_VAR\nBEGIN\nNetwork 1\n"
            "LD SM0.0\nMOVW #x, VW10\nNetwork 2\nLD I0.0\n= Q1.0\nEND_SUBROUTINE_BLOCK\n")
    py, nat = _run_both(text, scans=30)
    info = nat.backend
    reasons = {(b, n): why for b, n, why in info["python"]}
    assert reasons == {
        ("OB1", 2): "CTU is not lowered",
        ("OB1", 3): "PLS is not lowered",
        ("OB1", 4): "only 100 ms timers run natively",
        ("OB1", 5): "CALL is not lowered",
        ("SBR0", 1): "operand area L is not reached natively",
    }
    # OB1 networks 1 and 6 are two segments; SBR0 network 2 a third
    assert (info["pieces"], info["segments"]) == (3, 3)
    assert "_nseg0()" in nat.source and "_nseg2()" in nat.source


def test_blocks_with_jumps_and_loops_run_their_other_pieces_natively() -> None:
    """A jump may land on any piece: each lowered piece of such a block is
    its own segment; the jumps, labels and loops stay Python."""
    text = _ob1("LD I0.0\nJMP 1", "LD SM0.0\nINCW VW0", "LBL 1", "LD I0.1\n= Q0.0",
                "LD SM0.0\nFOR VW10, +1, +3", "LD SM0.0\nINCW VW2", "NEXT",
                "LD I0.0\nFOR VW12, +1, +2\nINCW VW4\nNEXT")
    py, nat = _run_both(text, scans=8)
    info = nat.backend
    assert info["python"] == [("OB1", 1, "JMP is not lowered"), ("OB1", 3, "LBL is not lowered"),
                              ("OB1", 5, "FOR is not lowered"), ("OB1", 7, "NEXT is not lowered"),
                              ("OB1", 8, "FOR is not lowered"), ("OB1", 8, "NEXT is not lowered")]
    # networks 2, 4 and 6 (a loop body in a network of its own: it starts
    # with the FOR's enable on the stack)
    assert info["pieces"] == info["segments"] == 3
    assert nat.mem.areas["V"][3] == 24 and nat.mem.areas["V"][5] == 8   # I0.0 on in 4 scans


def test_instrumented_program_runs_natively_with_the_same_coverage_and_breaks() -> None:
    """Coverage probes and breakpoints are machine code too: every piece is
    lowered, the counts equal the Python build's after every scan, and a
    breakpoint stops before the same network in the same scan, with the
    memory the network is about to read."""
    text = _ob1("LD I0.0\nA I0.1\nO M0.0\n= Q0.0", "LD I0.1\nAN I0.0\nINCW VW0\nLD SM0.0\n= Q0.1",
                "LD I0.0\nLPS\nA I0.1\n= Q0.2\nLPP\nON I0.1\nTON T37, +2")
    py, nat = _pair(text, instrument=True)
    assert nat.backend["python"] == [] and nat.backend["pieces"] == 3
    stops: dict[str, list] = {"python": [], "native": []}
    for plc in (py, nat):
        plc.coverage.breakpoints[1] = 1
        plc.coverage.on_break = (lambda net, plc=plc: stops[plc.backend["name"]].append(
            (net.name, plc.scans, bytes(plc.mem.areas["V"][:2]))))
    for k, ib0 in enumerate((0, 2, 3, 1, 0, 2, 2, 2)):
        for plc in (py, nat):
            plc.mem.areas["PI"][0] = ib0
            plc.scan()
        _same(py, nat, f"scan {k + 1}")
        assert nat.coverage.data() == py.coverage.data(), f"scan {k + 1}"
    assert stops["native"] == stops["python"]
    assert [s[:2] for s in stops["native"]] == [("OB1/2", k) for k in range(8)]
    # VW0 counts in scans 2, 6, 7, 8 (I0.1 without I0.0), after the stop
    assert [s[2][1] for s in stops["native"]] == [0, 0, 1, 1, 1, 1, 2, 3]
    assert nat.mem.areas["V"][1] == 4
    data = nat.coverage.data()
    assert data["contacts"]["OB1/1:5:1:A"] == 3 and data["outputs"]["OB1/3:21:1:TON"] == 3


def test_a_breakpoint_handler_writes_what_the_network_then_reads() -> None:
    """What the debugger sets while paused (memory, other breakpoints) is
    what the rest of the scan sees: nothing is kept in registers across
    the call."""
    text = _ob1("LD I0.0\n= Q0.0", "LD M0.0\n= Q0.1", "LD M0.1\n= Q0.2")
    for backend in ("python", "native"):
        plc = plcrt.load(text, backend=backend, instrument=True)
        seen = []

        def pause(net, plc=plc, seen=seen) -> None:
            seen.append(net.name)
            plc.mem.areas["M"][0] = 3            # as the debugger's `set M0.0 1`
            plc.coverage.breakpoints[:] = bytes([0, 0, 1])   # `next` moves on

        plc.coverage.breakpoints[1] = 1
        plc.coverage.on_break = pause
        plc.scan()
        assert seen == ["OB1/2", "OB1/3"], backend
        assert plc.mem.areas["Q"][0] == 0b110, backend


def test_machine_code_is_cached_on_disk_and_a_bad_file_is_compiled_again(
        tmp_path, monkeypatch) -> None:
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path))
    text = _ob1("LD I0.0\nA I0.1\n= Q0.7", "LD SM0.0\nINCW VW40")
    program_cache.clear()
    first = plcrt.load(text, backend="native")
    assert first.backend["cached"] is False
    files = list((tmp_path / "native").glob("*.native"))
    assert len(files) == 1
    program_cache.clear()
    second = plcrt.load(text, backend="native")
    assert second.backend["cached"] is True
    data = files[0].read_bytes()
    files[0].write_bytes(data[:-7] + b"garbage")       # a torn or foreign file
    program_cache.clear()
    third = plcrt.load(text, backend="native")
    assert third.backend["cached"] is False
    for plc in (first, second, third):
        plc.mem.areas["PI"][0] = 3
        plc.scan(3)
        assert plc.mem.areas["Q"][0] == 0x80 and plc.mem.areas["V"][41] == 3


def test_backend_option_errors(monkeypatch) -> None:
    with pytest.raises(PlcConfigError, match="backend must be one of"):
        plcrt.load(_ob1("LD I0.0\n= Q0.0"), backend="llvm")
    monkeypatch.setenv("PLCRT_BACKEND", "fast")
    with pytest.raises(PlcConfigError, match="PLCRT_BACKEND must be one of"):
        plcrt.load(_ob1("LD I0.0\n= Q0.0"))
    monkeypatch.setenv("PLCRT_BACKEND", "native")
    assert plcrt.load(_ob1("LD I0.0\n= Q0.0")).backend["name"] == "native"
    import plcrt.compiler.native.jit as jit
    monkeypatch.setattr(jit, "available", lambda: False)
    with pytest.raises(PlcConfigError, match="needs llvmlite"):
        plcrt.load(_ob1("LD I0.0\n= Q0.0"), backend="native")


TIMER_PROGRAM = _ob1("LD I0.0\nTON T37, +4\nLD T37\n= Q0.0",
                     "LD I0.1\nTON T40, +2\nLD T40\n= Q0.1", "LD SM0.0\nINCW VW0")


def test_snapshot_restore_and_fork_keep_the_native_timers() -> None:
    """A restore replaces the timer bank's arrays: the machine code must
    follow them, and a fork runs on its own memory."""
    py, nat = _pair(TIMER_PROGRAM, scan_ms=50)
    for plc in (py, nat):
        plc.mem.areas["PI"][0] = 3
        plc.scan(3)
    snaps = [plc.snapshot() for plc in (py, nat)]
    for plc in (py, nat):
        plc.scan(5)
    for plc, snap in zip((py, nat), snaps):
        plc.restore(snap)
    _same(py, nat, "after restore")
    twin = nat.fork()
    for plc in (py, nat, twin):
        plc.scan(4)
    _same(py, nat, "after restore and 4 scans")
    _same(py, twin, "fork")
    # 7 scans of 50 ms from t = 0: T37 (PT 4) holds 3 ticks, T40 (PT 2) is done
    assert nat.mem.areas["Q"][0] == 0b10 and nat.mem.areas["TV"][74:76] == b"\x00\x03"
    twin.mem.areas["PI"][0] = 0
    twin.scan()
    assert twin.mem.areas["TV"][74:76] == b"\x00\x00"
    assert nat.mem.areas["TV"][74:76] == b"\x00\x03"    # the fork's memory is its own


def test_forced_values_hold_on_the_native_backend() -> None:
    py, nat = _pair(_ob1("LD I0.0\n= Q0.0\nLD Q0.0\n= Q0.1", "LD SM0.0\nMOVW VW0, VW2"))
    for plc in (py, nat):
        plc.force("I0.0", 1)
        plc.force("Q0.0", 0)
        plc.force("VW0", 1234)
        plc.scan(2)
    _same(py, nat, "forced")
    # Q0.0 is forced off at the scan's end; inside the scan Q0.1 read the
    # program's Q0.0 (plcrt applies forces at the scan's start and end)
    assert nat.mem.areas["Q"][0] == 0b10 and nat.mem.areas["V"][2:4] == (1234).to_bytes(2, "big")
