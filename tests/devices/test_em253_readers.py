"""The EM253 blocks' inline readers: GET_AbsPos, SPD_CTRL, POS_GOTO_R,
HOMING and POS_RUN compute position, speed and travel themselves inside
the window of the axis's current segment (``Axis._w_lo`` .. ``_w_hi``)
and ask the axis otherwise.

Pinned here: nothing but the blocks reads the axes between the scans (no
``plc.axes()``, which would refresh the window), and the memory image of
every example still equals the exact run's after every scan, across the
segment ends of ramps and moves; a reader after a command in the same
scan (SET_AbsPos, a start, an E_Stop) sees the command's effect.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt
from plcrt.compiler import cache
from test_em253_fastpath import BLOCKS, EXAMPLES, _commands, _load, load_exact, lockstep

EM253 = Path(__file__).resolve().parents[2] / "programs" / "em253"
PLANT = {"module": {"0": {"axis": {"0": {"limit_neg": -10**9, "limit_pos": 10**9},
                                    "1": {}}}}}
EN3 = "CALL   MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4, VW0"
SPD = ("CALL   SPD_CTRL, 0, 0, +200, +200, +1000, +20000, VD100, VB104, M1.1, M1.2, M1.0, "
       "VW106, VD108")


def _memory(plc: plcrt.Plc) -> tuple[bytes, ...]:
    return tuple(bytes(b) for b in plc.mem.areas.values())


@pytest.mark.parametrize("seed", [0, 3])
@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_readers_alone_agree_with_the_exact_run(name: str, seed: int,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """Only the program reads the axes of the fast run (its memory is
    compared, the axes are not asked until the end): ramps end, moves
    start and end between two reads by the same block."""
    exact = load_exact(name, 1, monkeypatch)
    fast = _load(name, 1)
    scans = 6000
    commands = _commands(name, scans, 1, seed) if seed else iter([[]] * scans)
    lockstep(name, fast, exact, commands, _memory)
    assert [a.to_dict() for a in fast.axes()] == [a.to_dict() for a in exact.axes()]


def _ob1(*lines: str) -> str:
    body = ["ORGANIZATION_BLOCK MAIN:OB1", "TITLE=readers", "BEGIN", "Network 1",
            "LD     SM0.0", EN3]
    for i, line in enumerate(lines, 2):
        body += [f"Network {i}", "LD     SM0.0", line]
    return "\n".join(body + ["END_ORGANIZATION_BLOCK", ""])


def test_a_second_get_abspos_after_set_abspos_in_the_same_scan_reads_the_new_count() -> None:
    text = _ob1(SPD, "CALL   GET_AbsPos, 0, 0, VD120, VW124",
                "CALL   SET_AbsPos, 0, 0, VD10, M2.0, VW20",
                "CALL   GET_AbsPos, 0, 0, VD130, VW134")
    plc = plcrt.load(text, plant=PLANT, scan_ms=1.0)
    plc["M1.1"], plc["M1.0"] = 1, 1
    plc.run(seconds=0.5)                  # moving, inside a segment's window
    before = plc["VD130"]
    assert before == plc["VD120"] > 0
    plc["VD10"], plc["M2.0"] = -777, 1
    plc.scan()
    assert plc["VD120"] > before          # read before SET_AbsPos: still counting
    assert plc["VD130"] == -777           # same instant: the new count exactly
    assert plc["M2.0"] == 0
    plc.scan()
    assert plc["VD120"] == plc["VD130"] > -777


def test_readers_after_a_start_in_the_same_scan_see_the_new_move() -> None:
    """GET_AbsPos and SPD_CTRL read the axis before and after a POS_GOTO_R
    start in the same scan: before, the stopped axis; after, the move that
    starts at this instant (travel 0, SpdSs)."""
    goto = ("CALL   POS_GOTO_R, 0, 0, +100, +100, +3000, +9000, +50000, VD200, VB204, "
            "M3.1, M3.0, VW206, VD208, VD212")
    text = _ob1("CALL   GET_AbsPos, 0, 0, VD120, VW124", goto,
                "CALL   GET_AbsPos, 0, 0, VD130, VW134", goto.replace("VD2", "VD3")
                .replace("VB204", "VB304").replace("VW206", "VW306"))
    plc = plcrt.load(text, plant=PLANT, scan_ms=1.0)
    plc.run(seconds=0.1)
    plc["M3.0"] = 1
    plc.scan()
    assert plc["VD120"] == plc["VD130"] == 0
    assert plc["VW206"] == 1 and plc["VD212"] == 3000 and plc["VD208"] == 0
    # the second POS_GOTO_R is refused (the axis is busy): it reports nothing
    assert plc["VW306"] == 0 and plc["VD312"] == 0
    plc.run(seconds=0.05)
    pos = plc["VD130"]
    assert 0 < pos == plc["VD208"] and plc["VD212"] > 3000


def test_a_reader_after_e_stop_in_the_same_scan_sees_the_axis_stopped() -> None:
    spd2 = SPD.replace("M1.2", "M1.5").replace("VD100", "VD400").replace(
        "VB104", "VB404").replace("VW106", "VW406").replace("VD108", "VD408")
    text = _ob1(SPD, "CALL   GET_AbsPos, 0, 0, VD120, VW124", spd2,
                "CALL   GET_AbsPos, 0, 0, VD130, VW134")
    plc = plcrt.load(text, plant=PLANT, scan_ms=1.0)
    plc["M1.1"], plc["M1.0"] = 1, 1
    plc.run(seconds=0.3)
    assert plc["VD108"] == 20000 and plc["VD408"] == 0   # the second block idles
    plc["M1.5"] = 1          # E_Stop of the second SPD_CTRL: it does not own the move
    plc.scan()
    assert plc["VD108"] == 20000 and plc["VD120"] == plc["VD130"]
    plc["M1.5"], plc["M1.2"] = 0, 1   # E_Stop of the owner: the pulses stop at once
    plc.scan()
    assert plc["VD108"] == 0 and plc["VW106"] == 8
    stopped = plc["VD120"]
    assert plc["VD130"] == stopped
    plc.run(seconds=0.1)
    assert plc["VD120"] == plc["VD130"] == stopped


# ---------------------------------------------------------------------------
# one reader per axis, segment ends between scan starts
# ---------------------------------------------------------------------------

def _load_pair(text: str, plant: object, data: str | None,
               monkeypatch: pytest.MonkeyPatch) -> tuple[plcrt.Plc, plcrt.Plc]:
    """(fast, exact) PLCs of ``text`` at 0.7 ms scans: the segment ends of
    whole-millisecond ramps fall between two scan starts, so a reader
    that kept a segment past its end would extrapolate it."""
    fast = plcrt.load(text, plant=plant, data=data, scan_ms=0.7)
    with monkeypatch.context() as m:
        m.setattr(cache.programs, "max_entries", 0)
        for cls in BLOCKS:
            m.setattr(cls, "__call__", cls.call_exact)
        exact = plcrt.load(text, plant=plant, data=data, scan_ms=0.7)
    return fast, exact


GET0 = "CALL   GET_AbsPos, 0, 0, VD120, VW124"
STEEP_SPD = ("CALL   SPD_CTRL, 0, 0, +1, +1, +5000, +200000, VD100, VB104, M1.1, M1.2, "
             "M1.0, VW106, VD108")
STEEP_GOTO = ("CALL   POS_GOTO_R, 0, 0, +1, +1, +5000, +200000, +12345, VD100, VB104, "
              "M1.2, M1.0, VW106, VD108, VD112")
HOME = "CALL   HOMING, 0, 0, +1, +2000, +20000, +0, VD100, M1.2, M1.0, VW106, VD108"
ENVELOPE = ("CALL   POS_RUN, 0, 0, 0, +5000, &VB1000, 7, VD100, VB104, M1.2, M1.0, VW106, "
            "VD108, VD112, VB116")


@pytest.mark.parametrize("lines,plant,data", [
    ([STEEP_SPD], PLANT, None),
    ([GET0, STEEP_SPD], PLANT, None),
    ([STEEP_GOTO], PLANT, None),
    ([GET0, STEEP_GOTO], PLANT, None),
    ([HOME], str(EM253 / "homing_plant.toml"), None),
    ([GET0, HOME], str(EM253 / "homing_plant.toml"), None),
    ([ENVELOPE], PLANT, str(EM253 / "pos_run.db")),
    ([GET0, ENVELOPE], PLANT, str(EM253 / "pos_run.db")),
], ids=["spd", "get-spd", "goto", "get-goto", "homing", "get-homing", "pos_run",
        "get-pos_run"])
def test_a_lone_reader_never_uses_a_segment_past_its_end(
        lines: list[str], plant: object, data: str | None,
        monkeypatch: pytest.MonkeyPatch) -> None:
    fast, exact = _load_pair(_ob1(*lines), plant, data, monkeypatch)
    runs = {0: 1, 300: 0, 400: 1, 700: 0, 800: 1, 1100: 1}   # scan -> Run (M1.0)
    for k in range(4000):
        if k in runs:
            fast["M1.0"] = exact["M1.0"] = runs[k]
        fast.scan()
        exact.scan()
        assert _memory(fast) == _memory(exact), f"differs after scan {k}"
    assert [a.to_dict() for a in fast.axes()] == [a.to_dict() for a in exact.axes()]


def test_a_reader_whose_module_and_axis_change_between_calls(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """EmNo and AxisNo from memory: each change of either is a new search
    (another axis, or no module: the outputs kept), never the last one's."""
    spd1 = STEEP_SPD.replace(", 0, +1, +1, +5000, +200000", ", 1, +1, +1, +5000, +70000") \
        .replace("VD100", "VD200").replace("VB104", "VB204").replace("VW106", "VW206") \
        .replace("VD108", "VD208")
    text = _ob1(STEEP_SPD, spd1, "CALL   GET_AbsPos, VB50, VB51, VD120, VW124",
                STEEP_SPD.replace("SPD_CTRL, 0, 0", "SPD_CTRL, VB52, VB53")
                .replace("VD100", "VD300").replace("VB104", "VB304")
                .replace("VW106", "VW306").replace("VD108", "VD308"))
    fast, exact = _load_pair(text, PLANT, None, monkeypatch)
    sites = {0: (0, 0, 0, 1), 200: (0, 1, 0, 0), 400: (1, 1, 1, 0), 600: (0, 0, 0, 1),
             800: (0, 1, 0, 0)}
    for k in range(1000):
        for plc in (fast, exact):
            plc["M1.0"] = 1
            if k in sites:
                plc["VB50"], plc["VB51"], plc["VB52"], plc["VB53"] = sites[k]
        fast.scan()
        exact.scan()
        assert _memory(fast) == _memory(exact), f"differs after scan {k}"
    assert [str(d) for d in fast.diagnostics] == [str(d) for d in exact.diagnostics]


@pytest.mark.parametrize("block", [STEEP_SPD, STEEP_GOTO, HOME, ENVELOPE],
                         ids=["spd", "goto", "homing", "pos_run"])
def test_a_mover_whose_axis_changes_while_it_runs(block: str,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """The only mover of both axes takes its AxisNo from VB51: switched
    while its move runs (Run held), it reports the other axis, which it
    does not move."""
    plant = str(EM253 / "homing_plant.toml") if block is HOME else PLANT
    data = str(EM253 / "pos_run.db") if block is ENVELOPE else None
    text = _ob1(block.replace(", 0, 0, ", ", 0, VB51, ", 1).replace("+12345", "+1000000"))
    fast, exact = _load_pair(text, plant, data, monkeypatch)
    for k in range(1200):
        for plc in (fast, exact):
            plc["M1.0"] = 1
            if k in (150, 600, 900):
                plc["VB51"] = 1 - plc["VB51"]
        fast.scan()
        exact.scan()
        assert _memory(fast) == _memory(exact), f"differs after scan {k}"


@pytest.mark.parametrize("start,direction", [(2**31 - 30_000, 1), (-2**31 + 30_000, 0),
                                             (2**30 - 30_000, 1), (-2**30 + 30_000, 0)])
def test_get_abspos_wraps_the_counter_as_a_dint(start: int, direction: int,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """The counter set near the ends of a DINT (and near 2**30, where the
    shortcut's one-digit test changes) and run past them: C_Pos holds the
    counter's low 32 bits, signed, on the fast and the exact path."""
    text = _ob1("CALL   SET_AbsPos, 0, 0, VD10, M2.0, VW20", GET0,
                STEEP_SPD.replace("+200000", "+100000"))
    fast, exact = _load_pair(text, PLANT, None, monkeypatch)
    for plc in (fast, exact):
        plc["VD10"], plc["M2.0"] = start, 1
        plc.scan()
        plc["M1.1"], plc["M1.0"] = direction, 1
    seen = set()
    for k in range(1000):
        fast.scan()
        exact.scan()
        assert _memory(fast) == _memory(exact), f"differs after scan {k}"
        count = fast.module(0).axes[0].position(fast.now_us - 700)
        assert fast["VD120"] == (count + 2**31) % 2**32 - 2**31
        seen.add(count > 2**31 - 1 or count < -2**31)
    assert seen == {False, True} if abs(start) > 2**30 else seen == {False}


def test_a_restore_by_an_observer_inside_one_scan_call_reaches_the_terminals() -> None:
    """The scan loop stores a quiet module's terminal bytes itself (its
    ``held`` runs); an observer that restores a snapshot in the middle of
    one ``scan(n)`` replaces them: the scans after it store the restored
    module's bytes, as scan by scan."""
    runs: list[plcrt.Plc] = []
    for one_call in (True, False):
        plc = _load("spd_ctrl.awl", 1)
        for bit in ("M1.0", "M1.3"):
            plc[bit] = 0
        plc.scan(10)
        stopped = plc.snapshot()
        assert plc["QB2"] & 4 == 0                       # P off: no pulses
        for bit in ("M1.0", "M1.3"):
            plc[bit] = 1
        plc.scan(300)
        assert plc["QB2"] & 4                            # pulsing

        def back(p: plcrt.Plc, snap: plcrt.Plc = stopped) -> None:
            if p.scans == 400:
                p.restore(snap)

        plc.observers.append(back)
        if one_call:
            plc.scan(200)
        else:
            for _ in range(200):
                plc.scan()
        runs.append(plc)
    fast, ref = runs
    assert fast.scans == ref.scans and _memory(fast) == _memory(ref)
    assert fast["QB2"] & 4 == 0 and not fast.module(0).axes[0].segs
