"""PLS: the PTO and PWM generators of Q0.0 / Q0.1 (plcrt.engine.pulse;
System Manual, "Pulse Output (PLS)").  Counts and end times are analytic:
a train of N pulses of cycle c ends at start + N x c; a multi-segment
segment at start + N x c0 + delta x N(N-1)/2."""

from __future__ import annotations

import pytest

import plcrt
from plcrt.engine.pulse import Train


def program(ob1: str, int0: str = "LD SM0.0\nINCW VW0") -> str:
    out = ["ORGANIZATION_BLOCK MAIN:OB1", "BEGIN"]
    for i, net in enumerate(ob1.strip().split("\n\n"), 1):
        out += [f"Network {i}", *(ln.strip() for ln in net.strip().splitlines())]
    out += ["END_ORGANIZATION_BLOCK", "INTERRUPT_BLOCK INT_0:INT0", "BEGIN", "Network 1",
            *int0.splitlines(), "END_INTERRUPT_BLOCK"]
    return "\n".join(out) + "\n"


def pto(count: int, cycle: int, control: str = "16#85", extra: str = "") -> str:
    return (f"LD SM0.1\nMOVB {control}, SMB67\nMOVW +{cycle}, SMW68\nMOVD +{count}, SMD72\n"
            f"ATCH INT_0, 19\nENI\nPLS 0{extra}")


def test_a_single_segment_train_ends_and_interrupts_at_its_exact_time():
    """1000 pulses of 500 µs from t = 0: idle and event 19 at 0.5 s exactly."""
    plc = plcrt.load(program(pto(1000, 500) + "\n\nLD SM0.0\nMOVB SMB66, VB10"), scan_ms=7)
    plc.scan()
    assert plc["SM66.7"] == 0 and plc["VB10"] == 0
    assert plc.pulse[0].trains[0].end == 500_000
    plc.run("0.49s")
    assert plc.time == pytest.approx(0.497) and plc["VW0"] == 0
    plc.scan()                                   # interval (0.497, 0.504] holds 0.5 s
    assert plc["VW0"] == 1 and plc["SM66.7"] == 1
    assert plc.pulse[0].pulses_until(plc.now_us) == 1000


def test_the_ms_time_base_and_a_count_of_zero_meaning_one():
    """Control 16#8D: 1 ms time base; SMD72 = 0 sends one pulse (manual)."""
    plc = plcrt.load(program(pto(0, 20, "16#8D")))
    plc.scan()
    assert plc.pulse[0].trains[0].end == 20_000
    plc.run("20ms")
    assert plc["VW0"] == 1 and plc.pulse[0].pulses_until(plc.now_us) == 1


def test_the_pipeline_takes_one_train_and_refuses_the_next():
    ob1 = (pto(100, 1000) + "\n\nLD M0.0\nEU\nMOVD +50, SMD72\nPLS 0\n\n"
           "LD M0.1\nEU\nPLS 0")
    plc = plcrt.load(program(ob1))
    plc.scan()                                   # train 1: 0 .. 0.1 s
    plc["M0.0"] = 1
    plc.scan()                                   # train 2 waits
    plc["M0.1"] = 1
    plc.scan()                                   # a third: pipeline overflow
    assert plc["SM66.6"] == 1
    assert any("pipeline overflow" in d.message for d in plc.diagnostics)
    plc.run("0.2s")
    # train 2 started at the exact end of train 1 and ended 50 ms later
    assert plc["VW0"] == 1 and plc.pulse[0].pulses_until(plc.now_us) == 150
    assert plc.pulse[0].sent == 150


def test_disabling_aborts_the_train_and_sets_the_user_abort_bit():
    ob1 = pto(1000, 1000) + "\n\nLD M0.0\nMOVB 16#05, SMB67\nPLS 0"
    plc = plcrt.load(program(ob1))
    plc.run("0.1s")
    plc["M0.0"] = 1
    plc.scan()                                   # PLS with enable 0 at 0.1 s
    assert (plc["SM66.5"], plc["SM66.7"]) == (1, 1)
    assert plc.pulse[0].sent == 101              # edges at 0, 1, ..., 100 ms
    assert plc["VW0"] == 0                       # an aborted PTO does not complete


@pytest.mark.parametrize("c0, delta, n", [(1000, 0, 10), (1000, -10, 50), (500, 2, 200),
                                          (2000, -15, 100)])
def test_a_multi_segment_profile_takes_its_closed_form_time(c0, delta, n):
    """Profile at VB500: 2 segments; each lasts N c0 + delta N(N-1)/2 µs."""
    ob1 = (f"LD SM0.1\nMOVB 2, VB500\n"
           f"MOVW +{c0}, VW501\nMOVW {delta:+d}, VW503\nMOVD +{n}, VD505\n"
           f"MOVW +{c0 + (n - 1) * delta}, VW509\nMOVW +0, VW511\nMOVD +10, VD513\n"
           f"MOVB 16#A5, SMB67\nMOVW +500, SMW168\nATCH INT_0, 19\nENI\nPLS 0")
    plc = plcrt.load(program(ob1), scan_ms=1)
    plc.scan()
    seg1 = n * c0 + delta * n * (n - 1) // 2
    seg2 = 10 * (c0 + (n - 1) * delta)
    trains = plc.pulse[0].trains
    assert [t.end for t in trains] == [seg1, seg1 + seg2]
    plc.run((seg1 + seg2) / 1e6 + 0.002)
    assert plc["VW0"] == 1 and plc.pulse[0].sent == n + 10


def test_a_profile_whose_cycle_leaves_the_range_is_a_delta_error():
    ob1 = ("LD SM0.1\nMOVB 1, VB500\nMOVW +100, VW501\nMOVW -10, VW503\nMOVD +20, VD505\n"
           "MOVB 16#A5, SMB67\nMOVW +500, SMW168\nPLS 0")
    plc = plcrt.load(program(ob1))
    plc.scan()
    assert (plc["SM66.4"], plc["SM66.7"]) == (1, 1)
    assert any("delta calculation error" in d.message for d in plc.diagnostics)


def test_pulses_started_counts_rising_edges_in_closed_form():
    tr = Train(start=1000, count=5, c0=100, delta=-10)       # starts 1000, 1100, 1190, 1270, 1340
    assert [tr.pulses_started(t) for t in (999, 1000, 1099, 1100, 1339, 1340, 10**6)] == \
        [0, 1, 1, 2, 4, 5, 5]
    assert tr.end == 1000 + 5 * 100 - 10 * 10
    assert tr.level(1000) == 1 and tr.level(1050) == 0 and tr.level(1345) == 1


def test_pwm_drives_the_terminal_and_a_synchronous_update_waits_for_the_cycle_end():
    """PWM 10 ms cycle, 3 ms pulse; the terminal PQ0.0 is the pulse's level
    at the next scan start; an update with bit 4 takes effect at the end of
    the running cycle."""
    ob1 = ("LD SM0.1\nMOVB 16#CB, SMB67\nMOVW +10, SMW68\nMOVW +3, SMW70\nPLS 0\n\n"
           "LD M0.0\nEU\nMOVB 16#DB, SMB67\nMOVW +6, SMW70\nPLS 0")
    plc = plcrt.load(program(ob1), scan_ms=1)
    levels = []
    for _ in range(20):
        plc.scan()
        levels.append(plc.mem.areas["PQ"][0] & 1)    # the terminal
    # the scans end at 1..20 ms: high for 0 <= t mod 10 ms < 3 ms
    assert levels == [1, 1, 0, 0, 0, 0, 0, 0, 0, 1] * 2
    plc["M0.0"] = 1
    plc.scan()                      # at 20 ms: synchronous update, at 30 ms
    assert plc.pulse[0].pwm[2] == 3000
    plc.run("10ms")
    assert plc.pulse[0].pwm == (30_000, 10_000, 6000)


def test_a_fork_has_its_own_pulse_outputs():
    plc = plcrt.load(program(pto(1000, 1000)))
    plc.run("0.1s")
    twin = plc.fork()
    twin.run("0.1s")
    assert plc.pulse[0].pulses_until(plc.now_us) == 101
    assert twin.pulse[0].pulses_until(twin.now_us) == 201


@pytest.mark.parametrize("operand, message", [("2", "takes the constant 0"),
                                              ("VB0", "takes the constant 0")])
def test_pls_takes_output_0_or_1(operand, message):
    from plcrt.errors import PlcCompileError
    with pytest.raises(PlcCompileError) as e:
        plcrt.load(program(f"LD SM0.1\nPLS {operand}"))
    assert message in str(e.value)
