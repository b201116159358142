"""The scan loop's plain path (Plc.scan, Plc._replain).

A scan takes the plain path while nothing needs more than the program and
the devices: no force, no HDEF, no event source on the time line (PLS, a
timed or port interrupt, port traffic), no STOP requested, no plant wires
or encoders, no watchdog counting.  The loop tests one flag, recomputed
whenever any of these changes, and the observers at each scan's end.

Pinned here, each with a change made *inside* one ``scan(n)`` call (by an
observer, a device, or the program) and one made between calls: the
scans after the change are those of the exact path (forces applied at
the start and the end, timed interrupts run, STOP taken, observers
called), and the flag comes back once the change is undone.
"""

from __future__ import annotations

from typing import Any

import pytest

import plcrt

COPY = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD I0.0\n= Q0.0\n"
        "Network 2\nLD SM0.0\nINCW VW0\nEND_ORGANIZATION_BLOCK\n")


def test_a_program_without_special_needs_is_plain() -> None:
    assert plcrt.load(COPY)._plain


def test_a_force_made_by_an_observer_inside_one_scan_call_holds_from_the_next_scan() -> None:
    plc = plcrt.load(COPY)
    seen: list[int] = []

    def obs(p: plcrt.Plc) -> None:
        seen.append(p["Q0.0"])
        if p.scans == 3:
            p.force("I0.0", 1)

    plc.observers.append(obs)
    plc.scan(6)
    assert seen == [0, 0, 0, 1, 1, 1]
    plc.observers.clear()
    plc.scan(2)          # plain again but for the force: still held
    assert plc["Q0.0"] == 1 and not plc._plain
    plc.unforce("I0.0")
    assert plc._plain
    plc["I0.0"] = 0
    plc.scan()
    assert plc["Q0.0"] == 0


def test_a_forced_output_is_written_at_the_scan_end_after_a_force_between_calls() -> None:
    plc = plcrt.load(COPY)
    plc["I0.0"] = 1
    plc.scan(2)
    plc.force("Q0.0", 0)
    plc.scan(3)
    assert plc["Q0.0"] == 0 and plc.mem.areas["PQ"][0] & 1 == 0
    plc.unforce()
    assert plc._plain
    plc.scan()
    assert plc.mem.areas["PQ"][0] & 1 == 1


def test_observers_added_and_removed_between_and_inside_scan_calls() -> None:
    plc = plcrt.load(COPY)
    calls: list[int] = []
    late: list[int] = []

    def second(p: plcrt.Plc) -> None:
        late.append(p.scans)

    def first(p: plcrt.Plc) -> None:
        calls.append(p.scans)
        if p.scans == 3:
            p.observers.append(second)   # runs from this very scan end on
        if p.scans == 5:
            p.observers.remove(second)

    plc.scan(2)
    plc.observers.append(first)
    plc.scan(4)
    assert calls == [3, 4, 5, 6] and late == [3, 4]
    plc.observers.clear()
    plc.scan(3)
    assert calls == [3, 4, 5, 6] and plc.scans == 9 and plc["VW0"] == 9

    plc2 = plcrt.load(COPY)
    plc2.observers.append(first)
    plc2.scan(6)
    assert calls[4:] == [1, 2, 3, 4, 5, 6] and late == [3, 4, 3, 4]


STOP_AT = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD SM0.0\nINCW VW0\n"
           "Network 2\nLDW= VW0, 5\nSTOP\nEND_ORGANIZATION_BLOCK\n")


def test_stop_in_the_program_ends_a_long_scan_call_after_its_scan() -> None:
    plc = plcrt.load(STOP_AT)
    plc.scan(20)
    assert plc.mode == "STOP" and plc.scans == 5 and plc["VW0"] == 5


TIMED = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD SM0.1\nMOVB 5, SMB34\nATCH INT_0, 10\n"
         "ENI\nNetwork 2\nLD I0.1\nDTCH 10\nEND_ORGANIZATION_BLOCK\n"
         "INTERRUPT_BLOCK INT_0:INT0\nBEGIN\nNetwork 1\nLD SM0.0\nINCW VW10\n"
         "END_INTERRUPT_BLOCK\n")


def test_a_timed_interrupt_attached_by_the_program_runs_inside_one_scan_call() -> None:
    plc = plcrt.load(TIMED, scan_ms=1)
    plc.scan(100)          # attached in the first scan: every 5 ms up to 100 ms
    assert plc["VW10"] == 20 and not plc._plain
    plc["I0.1"] = 1        # DTCH: the time line has nothing more to do
    plc.scan(10)
    assert plc._plain
    done = plc["VW10"]
    plc.scan(50)
    assert plc["VW10"] == done


def _reference(text: str, **kw: Any) -> plcrt.Plc:
    """The program on a PLC that never takes the plain path."""
    ref = plcrt.load(text, **kw)
    ref._replain = lambda: setattr(ref, "_plain", False)   # type: ignore[method-assign]
    ref._replain()
    return ref


PLS = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD SM0.1\nMOVB 16#8D, SMB67\n"
       "MOVW 4, SMW68\nMOVD 3, SMD72\nPLS 0\nNetwork 2\nLD SM0.0\nINCW VW0\n"
       "END_ORGANIZATION_BLOCK\n")


def test_a_pulse_train_started_by_the_program_drives_its_output_inside_one_scan_call() -> None:
    """PLS 0 in the first scan: from then on the scans are those of the
    exact path (the terminal Q0.0 follows the pulse train)."""
    levels: dict[str, list[bytes]] = {"fast": [], "ref": []}
    for key, plc in (("fast", plcrt.load(PLS, scan_ms=0.5)), ("ref", _reference(PLS, scan_ms=0.5))):
        for _ in range(40):
            plc.scan()
            levels[key].append(bytes(plc.mem.areas["PQ"]) + bytes(plc.mem.areas["V"][:2]))
        assert not plc._plain
    assert levels["fast"] == levels["ref"]
    assert len({lv[0] & 1 for lv in levels["ref"]}) == 2   # the output does pulse


@pytest.mark.parametrize("attr", ["_sources_on", "stop_requested"])
def test_the_setters_recompute_the_flag(attr: str) -> None:
    plc = plcrt.load(COPY)
    setattr(plc, attr, True)
    assert not plc._plain
    setattr(plc, attr, False)
    assert plc._plain


class _Setter:
    """A device that, at a given scan, turns the time line's sources on (as
    the port devices do when traffic starts) or requests STOP."""

    slot = None

    def __init__(self, at: int, what: str) -> None:
        self.at, self.what = at, what

    def step(self, plc: Any, t_from: int, t_to: int) -> None:
        if plc.scans == self.at:
            if self.what == "stop":
                plc.request_stop()
            else:
                plc._sources_on = True


def test_a_device_that_turns_sources_on_ends_the_plain_path_at_once() -> None:
    plc = plcrt.load(COPY)
    plc.devices.append(_Setter(4, "sources"))
    plc.scan(8)
    assert plc.scans == 8 and not plc._plain and plc["VW0"] == 8


def test_a_device_that_requests_stop_stops_at_the_end_of_that_scan() -> None:
    plc = plcrt.load(COPY)
    plc.devices.append(_Setter(4, "stop"))
    plc.scan(8)
    assert plc.mode == "STOP" and plc.scans == 5 and plc["VW0"] == 5


TIMED_EARLY = TIMED.replace("MOVB 5, SMB34", "MOVB 1, SMB34")


@pytest.mark.parametrize("scan_ms", [1, 7])
def test_an_interrupt_attached_in_a_scan_fires_in_that_scans_time_line(scan_ms: int) -> None:
    """ATCH of a 1 ms timed interrupt in the first scan: at 7 ms scans it
    fires 7 times inside that very scan, as on the exact path."""
    fast, ref = plcrt.load(TIMED_EARLY, scan_ms=scan_ms), _reference(TIMED_EARLY, scan_ms=scan_ms)
    for k in range(12):
        fast.scan()
        ref.scan()
        assert fast["VW10"] == ref["VW10"], k
    assert ref["VW10"] == 12 * scan_ms


def test_a_fork_and_a_restore_take_the_flag_of_their_source() -> None:
    plc = plcrt.load(COPY)
    before = plc.snapshot()
    plc.force("I0.0", 1)
    twin = plc.fork()
    assert not twin._plain
    twin.scan(2)
    assert twin["Q0.0"] == 1
    plc.restore(before)
    assert plc._plain and plc.forces == {}
    before.force("I0.0", 1)
    twin.restore(before)
    assert not twin._plain


HDEF = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD SM0.1\nMOVB 16#F8, SMB37\n"
        "HDEF 0, 0\nHSC 0\nEND_ORGANIZATION_BLOCK\n")


def test_a_counter_defined_by_the_program_counts_inside_one_scan_call() -> None:
    """HDEF 0 (mode 0, clock I0.0) in the first scan: the edges of I0.0
    set between later scans are counted at each scan start."""
    plc = plcrt.load(HDEF, scan_ms=1)
    plc.scan(1)
    assert not plc._plain
    for _ in range(5):
        plc["I0.0"] = 1
        plc.scan(2)
        plc["I0.0"] = 0
        plc.scan(2)
    assert plc["HC0"] == 5
