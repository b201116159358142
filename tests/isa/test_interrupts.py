"""Interrupt instructions (ATCH DTCH ENI DISI RETI CRETI CEVNT) and the
interrupt system's timing (plcrt.engine.interrupts; System Manual,
"Interrupt instructions"; docs/decisions.md, "Interrupts").

The time model pinned here: the main program runs at the scan's start
instant; a timed interrupt runs its routine at its exact time inside the
scan interval (after the main program, before the next scan); an input edge
from the outside runs its routine at the scan's start, before the image is
read; ENI runs what is queued at the ENI.
"""

from __future__ import annotations

import pytest

import plcrt
from plcrt.errors import PlcCompileError


def program(ob1: str, *ints: str) -> str:
    """OB1 (networks separated by blank lines) and INT0, INT1, ... bodies."""
    out = ["ORGANIZATION_BLOCK MAIN:OB1", "BEGIN"]
    for i, net in enumerate(ob1.strip().split("\n\n"), 1):
        out += [f"Network {i}", *(ln.strip() for ln in net.strip().splitlines())]
    out.append("END_ORGANIZATION_BLOCK")
    for k, body in enumerate(ints):
        out += [f"INTERRUPT_BLOCK INT_{k}:INT{k}", "BEGIN"]
        for i, net in enumerate(body.strip().split("\n\n"), 1):
            out += [f"Network {i}", *(ln.strip() for ln in net.strip().splitlines())]
        out.append("END_INTERRUPT_BLOCK")
    return "\n".join(out) + "\n"


COUNT = "LD SM0.0\nINCW VW0"            # INT0 counts its runs in VW0
STAMP = "LD SM0.0\nINCW VW2"            # INT1 counts in VW2


def timed(interval_ms: int, scan_ms: float, seconds: float = 1.0) -> int:
    plc = plcrt.load(program(f"LD SM0.1\nMOVB {interval_ms}, SMB34\nATCH INT_0, 10\nENI",
                             COUNT), scan_ms=scan_ms)
    plc.run(seconds)
    return plc["VW0"]


@pytest.mark.parametrize("interval_ms, scan_ms, expected", [
    (10, 10, 100), (1, 10, 1000), (1, 1, 1000), (7, 10, 142), (255, 10, 3),
    (10, 3, 100), (5, 0.5, 200), (3, 7, 333),
])
def test_timed_interrupt_counts_over_one_simulated_second(interval_ms, scan_ms, expected):
    """Attached at t = 0 by the first scan: it runs at k x interval for every
    k x interval <= 1 s, whatever the scan time."""
    assert timed(interval_ms, scan_ms) == expected


def test_timed_interrupt_1_uses_smb35_and_both_run():
    plc = plcrt.load(program("LD SM0.1\nMOVB 4, SMB34\nMOVB 10, SMB35\nATCH INT_0, 10\n"
                             "ATCH INT_1, 11\nENI", COUNT, STAMP))
    plc.run(1.0)
    assert (plc["VW0"], plc["VW2"]) == (250, 100)


def test_a_timed_routine_runs_at_its_exact_time_after_the_main_program():
    """INT0 copies VW10 (written by OB1 every scan) at 3, 6, 9, 12 ms: the
    routine at 9 ms sees the value OB1 wrote at the scan start at 0 ms."""
    ob1 = ("LD SM0.1\nMOVB 3, SMB34\nATCH INT_0, 10\nENI\n\n"
           "LD SM0.0\nINCW VW10")
    plc = plcrt.load(program(ob1, "LD SM0.0\nINCW VW0\nMOVW VW10, VW20"), scan_ms=10)
    plc.scan()            # scan at 0 ms: VW10 = 1; routines at 3, 6, 9 ms
    assert (plc["VW0"], plc["VW20"]) == (3, 1)
    plc.scan()            # scan at 10 ms: VW10 = 2; routines at 12, 15, 18 ms
    assert (plc["VW0"], plc["VW20"]) == (6, 2)


def test_attaching_every_scan_restarts_the_timing_and_is_diagnosed():
    """ATCH on SM0.0 restarts the interval each scan: a 20 ms interrupt never
    fires at 10 ms scans, as on the CPU, and plcrt says why."""
    plc = plcrt.load(program("LD SM0.0\nMOVB 20, SMB34\nATCH INT_0, 10\nENI", COUNT))
    plc.run(1.0)
    assert plc["VW0"] == 0
    assert any("attached again before its first interval" in d.message
               for d in plc.diagnostics)


def test_interval_zero_never_fires_and_is_diagnosed():
    plc = plcrt.load(program("LD SM0.1\nATCH INT_0, 10\nENI", COUNT))
    plc.run(0.5)
    assert plc["VW0"] == 0
    assert any("SMB34 = 0" in d.message for d in plc.diagnostics)


@pytest.mark.parametrize("port, event", [(0, 9), (1, 26)])
def test_a_transmit_complete_event_runs_its_routine(port, event):
    """The ports are simulated (plcrt.engine.ports): XMT of 3 characters at
    9600 baud 8N1 ends 3 x 10 / 9600 s = 3125 µs later, and the attached
    routine of the port's transmit-complete event runs then."""
    ctrl = "SMB30" if port == 0 else "SMB130"
    plc = plcrt.load(program(f"LD SM0.1\nMOVB 16#09, {ctrl}\nMOVB 3, VB100\n"
                             f"ATCH INT_0, {event}\nENI\nXMT VB100, {port}", COUNT))
    plc.scan()
    assert plc["VW0"] == 1
    assert not any("never runs" in d.message for d in plc.diagnostics)


@pytest.mark.parametrize("event", [24, 25, 26])
def test_attaching_an_event_of_a_port_the_cpu_lacks_is_diagnosed(event):
    """A CPU 224 has port 0 only: the events of port 1 never occur, and ATCH
    says so instead of leaving the learner to wonder."""
    plc = plcrt.load(program(f"LD SM0.1\nATCH INT_0, {event}\nENI", COUNT), cpu="CPU224")
    plc.run(0.1)
    assert plc["VW0"] == 0
    assert any(f"event {event} (port 1" in d.message and "never runs" in d.message
               for d in plc.diagnostics)


def test_interrupts_start_disabled_and_queue_until_eni_with_overflow_bits():
    """RUN starts with interrupts disabled: occurrences queue (8 in the timed
    group), the ninth is lost and sets SM4.2; ENI runs the queue at once and
    SM4.2 reads 1 inside those routines, 0 once the queue is empty."""
    ob1 = ("LD SM0.1\nMOVB 1, SMB34\nATCH INT_0, 10\n\n"
           "LD M0.0\nENI")
    plc = plcrt.load(program(ob1, "LD SM0.0\nINCW VW0\n\nLD SM4.2\nINCW VW4"), scan_ms=10)
    plc.run("50ms")
    assert plc["VW0"] == 0 and plc["SM4.2"] == 1
    plc["M0.0"] = 1
    plc.scan()            # ENI at 50 ms: 8 queued routines, then 51..60 ms
    assert plc["VW0"] == 18
    assert plc["VW4"] == 8                     # the queued ones saw the overflow bit
    assert plc["SM4.2"] == 0
    assert any("timed queue holds 8 events" in d.message for d in plc.diagnostics)


def test_disi_queues_and_dtch_ignores():
    ob1 = ("LD SM0.1\nMOVB 10, SMB34\nATCH INT_0, 10\nENI\n\n"
           "LD M0.1\nDISI\n\n"
           "LD M0.2\nDTCH 10\n\n"
           "LD M0.3\nENI")
    plc = plcrt.load(program(ob1, COUNT), scan_ms=10)
    plc.run("100ms")
    assert plc["VW0"] == 10
    plc["M0.1"] = 1
    plc.run("30ms")                             # 3 occurrences queued
    assert plc["VW0"] == 10
    plc["M0.1"], plc["M0.3"] = 0, 1
    plc.scan()                                  # ENI: the 3 run, then one more
    assert plc["VW0"] == 14
    plc["M0.2"] = 1
    plc.run("100ms")                            # detached: nothing more
    assert plc["VW0"] == 14


def test_input_edges_run_their_routines_at_the_scan_start():
    """Events 0/1: I0.0 rising and falling, one routine run per edge, at the
    start of the scan after the input changed (LDI reads the new input)."""
    ob1 = "LD SM0.1\nATCH INT_0, 0\nATCH INT_1, 1\nENI"
    int0 = "LD I0.0\n= M1.0\n\nLDI I0.0\n= M1.1\n\nLD SM0.0\nINCW VW0"
    plc = plcrt.load(program(ob1, int0, STAMP))
    plc.scan()
    plc["I0.0"] = 1
    plc.scan()
    assert (plc["VW0"], plc["VW2"], plc["M1.1"]) == (1, 0, 1)
    plc["I0.0"] = 0
    plc.scan()
    assert (plc["VW0"], plc["VW2"]) == (1, 1)


def test_priorities_discrete_before_timed_at_the_same_instant():
    """An edge and a timed occurrence both queued while disabled: ENI runs
    the discrete group first (INT1 sees VW0 = 0 in VW6)."""
    ob1 = ("LD SM0.1\nMOVB 10, SMB34\nATCH INT_0, 10\nATCH INT_1, 0\n\n"
           "LD M0.0\nENI")
    plc = plcrt.load(program(ob1, COUNT, "LD SM0.0\nMOVW VW0, VW6\nINCW VW2"))
    plc.scan()                          # timed at 10 ms queued
    plc["I0.0"] = 1
    plc["M0.0"] = 1
    plc.scan()                          # edge at 10 ms queued; ENI runs both
    assert (plc["VW2"], plc["VW6"], plc["VW0"]) == (1, 0, 2)


def test_a_routine_does_not_change_the_main_programs_accumulators_and_status_bits():
    ob1 = ("LD SM0.1\nMOVB 1, SMB34\nATCH INT_0, 10\nENI\n\n"
           "LD SM0.0\nMOVD 12345, AC0\nMOVD AC0, VD20")
    int0 = "LD SM0.0\nMOVD 0, AC0\n-I 1, VW30\nINCW VW0"
    plc = plcrt.load(program(ob1, int0))
    plc.run("100ms")
    assert plc["VW0"] == 100 and plc["AC0"] == 12345
    assert plc["SM1.0"] == 0                   # the routine's zero result is not kept


def test_creti_and_reti_return_from_the_routine():
    int0 = "LD M0.0\nCRETI\n\nLD SM0.0\nINCW VW0\nRETI\n\nLD SM0.0\nINCW VW4"
    plc = plcrt.load(program("LD SM0.1\nMOVB 10, SMB34\nATCH INT_0, 10\nENI", int0))
    plc.run("100ms")
    assert (plc["VW0"], plc["VW4"]) == (10, 0)
    plc["M0.0"] = 1
    plc.run("100ms")
    assert plc["VW0"] == 10


def test_cevnt_clears_the_queued_occurrences_of_its_event():
    ob1 = ("LD SM0.1\nMOVB 10, SMB34\nATCH INT_0, 10\n\n"
           "LD M0.0\nCEVNT 10\n\nLD M0.1\nENI")
    plc = plcrt.load(program(ob1, COUNT))
    plc.run("50ms")
    plc["M0.0"], plc["M0.1"] = 1, 1
    plc.scan()          # CEVNT drops the 5 queued, then ENI: only 60 ms runs
    assert plc["VW0"] == 1


def test_a_fork_keeps_its_own_interrupt_state():
    plc = plcrt.load(program("LD SM0.1\nMOVB 10, SMB34\nATCH INT_0, 10\nENI", COUNT))
    plc.run("100ms")
    twin = plc.fork()
    twin.run("100ms")
    assert (plc["VW0"], twin["VW0"]) == (10, 20)


@pytest.mark.parametrize("ob1, ints, message", [
    ("LD SM0.1\nATCH INT_5, 10", (COUNT,), "no interrupt routine named 'INT_5'"),
    ("LD SM0.1\nATCH INT_0, 40", (COUNT,), "event 40 is not in the S7-200's event table"),
    ("LD SM0.1\nATCH INT_0, VB0", (COUNT,), "EVNT must be a constant event number"),
    ("LD SM0.1\nATCH INT_0", (COUNT,), "takes an interrupt routine and an event"),
    ("LD SM0.1\nRETI", (COUNT,), "RETI is only allowed in an interrupt routine"),
    ("LD SM0.1\nCRETI", (COUNT,), "CRETI is only allowed in an interrupt routine"),
    ("LD SM0.1\nATCH INT_0, 10", ("LD SM0.0\nENI",), "ENI is not allowed in an interrupt"),
    ("LD SM0.1\nATCH INT_0, 10", ("LD SM0.0\nDISI",), "DISI is not allowed in an interrupt"),
    ("LD SM0.1\nATCH INT_0, 10", ("LD SM0.0\nEND",), "END is only allowed in the main"),
    ("LD SM0.1\nDTCH 99", (COUNT,), "event 99 is not in the S7-200's event table"),
])
def test_what_the_cpu_refuses_is_a_located_compile_error(ob1, ints, message):
    with pytest.raises(PlcCompileError) as e:
        plcrt.load(program(ob1, *ints))
    assert message in str(e.value)


def test_the_debugger_breaks_in_a_routine_at_the_interrupts_time():
    import io

    from plcrt.debug.session import Session
    plc = plcrt.load(program("LD SM0.1\nMOVB 4, SMB34\nATCH INT_0, 10\nENI", COUNT),
                     instrument=True)
    out = io.StringIO()
    s = Session(plc, out=out)
    s.run(["break INT0/1", "run 1", "print VW0", "continue", "continue", "quit"])
    text = out.getvalue()
    assert "break at INT0/1 (t=0.004 s, an interrupt in scan 1)" in text
    assert "break at INT0/1 (t=0.008 s, an interrupt in scan 1)" in text
    assert "VW0 = 0" in text


def test_coverage_counts_the_networks_of_interrupt_routines():
    """Coverage sees a routine's networks when its event occurred (INT0),
    not those of a routine whose event never came (INT1 on I0.1)."""
    plc = plcrt.load(program("LD SM0.1\nMOVB 4, SMB34\nATCH INT_0, 10\nATCH INT_1, 2\nENI",
                             COUNT, STAMP), instrument=True)
    plc.run("20ms")
    ran = plc.coverage.data()["networks"]
    assert ran["INT0/1"] == 1 and ran["INT1/1"] == 0 and ran["OB1/1"] == 1


def test_t32_ct_pt_interrupts_at_the_exact_millisecond_and_reads_pt():
    """Event 21: T32 (1 ms TON) started at 0 with PT 25 reaches it at 25 ms,
    inside the third 10 ms scan; the routine reads T32 = 25 (1 ms timers
    count every ms), and the main program sees the bit at the next scan."""
    ob1 = "LD SM0.1\nATCH INT_0, 21\nENI\n\nLD SM0.0\nTON T32, +25"
    plc = plcrt.load(program(ob1, "LD SM0.0\nINCW VW0\nMOVW T32, VW2\nMOVW VW2, VW4"))
    plc.scan(2)
    assert plc["VW0"] == 0
    plc.scan()                       # interval (20, 30] ms holds 25 ms
    assert (plc["VW0"], plc["VW2"]) == (1, 25)
    plc.scan(3)
    assert plc["VW0"] == 1 and plc["T32"] == 50   # once; the timer counts on (50 ms scan)
    assert plc["T32:BIT"] == 1


def test_a_routine_reads_the_1ms_timers_of_its_own_time():
    ob1 = ("LD SM0.1\nMOVB 3, SMB34\nATCH INT_0, 10\nENI\n\n"
           "LD SM0.0\nTON T96, +1000")
    plc = plcrt.load(program(ob1, "LD SM0.0\nMOVW T96, VW2"), scan_ms=10)
    plc.scan(2)
    # routines at 3, 6, 9, 12, 15, 18 ms; T96 started at 0 ms
    assert plc["VW2"] == 18
    plc.scan()
    assert plc["T96"] == 30 and plc["VW2"] == 30   # the routine at 30 ms, the end of (20, 30]


def test_a_trace_records_what_the_routines_did_in_each_scan():
    """Samples are taken at the end of each scan: a 1 ms routine counting in
    VW0 adds 10 per 10 ms scan."""
    from plcrt.trace.recorder import Trace
    plc = plcrt.load(program("LD SM0.1\nMOVB 1, SMB34\nATCH INT_0, 10\nENI", COUNT))
    tr = Trace(plc, ["VW0"])
    plc.run("50ms")
    assert list(tr["VW0"]) == [10, 20, 30, 40, 50]


def test_a_pto_wired_to_i0_0_interrupts_at_every_exact_edge():
    """Q0.0 wired to I0.0, events 0 and 1: 200 pulses of 1 ms from t = 0
    rise at k ms and fall at k ms + 0.5 ms; the routines stamp T32-free
    times by counting, and the last rising edge's routine runs at 199 ms."""
    ob1 = ("LD SM0.1\nATCH INT_0, 0\nATCH INT_1, 1\nENI\n"
           "MOVB 16#85, SMB67\nMOVW +1000, SMW68\nMOVD +200, SMD72\nPLS 0")
    plc = plcrt.load(program(ob1, COUNT, STAMP), plant='[cpu]\nwire = { "I0.0" = "Q0.0" }\n')
    times: list[int] = []
    plc._int_fns[0] = (lambda fn: lambda l: (times.append(plc._irq_t), fn(l)))(plc._int_fns[0])
    plc.run("0.3s")
    assert (plc["VW0"], plc["VW2"]) == (200, 200)
    assert times[:3] == [0, 1000, 2000] and times[-1] == 199_000


def test_an_encoder_on_i0_0_interrupts_at_its_edges_and_sets_the_input():
    """1000 Hz on I0.0 from 0.1 s to 0.5 s: 401 rising edges (the first at
    0.1 s), 400 falling ones; I0.0 reads the signal's level at scan starts."""
    enc = '[[cpu.encoder]]\ninputs = ["I0.0"]\nhz = 1000\nstart = 0.1\nstop = 0.5\n'
    plc = plcrt.load(program("LD SM0.1\nATCH INT_0, 0\nATCH INT_1, 1\nENI", COUNT, STAMP),
                     plant=enc, scan_ms=1.25)
    plc.run("1s")
    assert (plc["VW0"], plc["VW2"]) == (401, 400)
    plc2 = plcrt.load(program("LD SM0.0\n= M0.0"), plant=enc, scan_ms=0.25)
    seen = []
    plc2.observers.append(lambda p: seen.append(p["I0.0"]))
    plc2.run("0.11s")
    # scan k starts at k x 250 µs and reads the level then: high in the
    # first half of each ms from 0.1 s (scan 0 reads the power-up 0)
    expected = [0] + [1 if 100_000 <= t < 500_000 and (t - 100_000) % 1000 < 500 else 0
                      for t in range(250, 110_001, 250)]
    assert seen == expected[:len(seen)] and len(seen) == 440
