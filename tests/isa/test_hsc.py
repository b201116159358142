"""HDEF / HSC: the high-speed counters (plcrt.engine.hsc; System Manual,
"High-Speed Counter instructions").  Inputs changed between scans are
counted at the next scan start; a counter on a pulse output (mode 12, or a
clock input wired to Q0.0 in the plant) counts it exactly and reaches CV=PV
at the exact µs of the pulse."""

from __future__ import annotations

import pytest

import plcrt
from plcrt.errors import PlcCompileError, PlcConfigError


def program(ob1: str, int0: str = "LD SM0.0\nINCW VW0\nMOVD HC0, VD10") -> str:
    out = ["ORGANIZATION_BLOCK MAIN:OB1", "BEGIN"]
    for i, net in enumerate(ob1.strip().split("\n\n"), 1):
        out += [f"Network {i}", *(ln.strip() for ln in net.strip().splitlines())]
    out += ["END_ORGANIZATION_BLOCK", "INTERRUPT_BLOCK INT_0:INT0", "BEGIN", "Network 1",
            *int0.splitlines(), "END_INTERRUPT_BLOCK"]
    return "\n".join(out) + "\n"


def counter(mode: int, control: str = "16#F8", pv: int = 5, n: int = 0, extra: str = "") -> str:
    sm = {0: 37, 1: 47, 2: 57, 4: 147}[n]
    return (f"LD SM0.1\nMOVB {control}, SMB{sm}\nMOVD {pv:+d}, SMD{sm + 5}\nHDEF {n}, {mode}\n"
            f"HSC {n}\nATCH INT_0, {({0: 12, 1: 13, 2: 16, 4: 29})[n]}\nENI{extra}")


def pulses(plc, bit: str, k: int) -> None:
    for _ in range(k):
        plc[bit] = 1
        plc.scan()
        plc[bit] = 0
        plc.scan()


def test_mode_0_counts_rising_edges_up_and_interrupts_at_pv():
    plc = plcrt.load(program(counter(0)))
    plc.scan()
    pulses(plc, "I0.0", 7)
    assert plc["HC0"] == 7
    assert plc["VW0"] == 1 and plc["VD10"] == 5          # CV=PV at the fifth edge
    assert plc["SM36.5"] == 1 and plc["SM36.7"] == 1      # counting up, CV > PV


def test_mode_0_counts_down_with_control_bit_3_clear():
    plc = plcrt.load(program(counter(0, "16#F0", pv=-2)))
    plc.scan()
    pulses(plc, "I0.0", 3)
    assert plc["HC0"] == -3 and plc["VW0"] == 1 and plc["SM36.5"] == 0


def test_mode_3_takes_its_direction_from_i0_1_and_reports_changes():
    """Event 27: HSC0 direction changed."""
    ob1 = counter(3, pv=100) + "\nATCH INT_0, 27"
    plc = plcrt.load(program(ob1, "LD SM0.0\nINCW VW0"))
    plc.scan()                        # enabled with I0.1 = 0: counting down
    pulses(plc, "I0.0", 2)
    assert plc["HC0"] == -2 and plc["VW0"] == 0
    plc["I0.1"] = 1
    plc.scan()                        # up: a direction change
    pulses(plc, "I0.0", 5)
    assert plc["HC0"] == 3
    assert plc["VW0"] == 1


def test_mode_6_has_an_up_and_a_down_clock():
    plc = plcrt.load(program(counter(6, pv=100)))
    plc.scan()
    pulses(plc, "I0.0", 5)
    pulses(plc, "I0.1", 2)
    assert plc["HC0"] == 3


@pytest.mark.parametrize("control, expected", [("16#F8", 8), ("16#FC", 2)])
def test_mode_9_quadrature_counts_x4_or_x1(control, expected):
    """Two full A/B cycles forward (A leads B): 8 steps at x4, 2 at x1."""
    plc = plcrt.load(program(counter(9, control, pv=100)))
    plc.scan()
    for _ in range(2):
        for a, b in ((1, 0), (1, 1), (0, 1), (0, 0)):
            plc["I0.0"], plc["I0.1"] = a, b
            plc.scan()
    assert plc["HC0"] == expected
    for a, b in ((0, 1), (1, 1), (1, 0), (0, 0)):          # one cycle back
        plc["I0.0"], plc["I0.1"] = a, b
        plc.scan()
    assert plc["HC0"] == expected - expected // 2


def test_quadrature_a_and_b_changing_together_is_diagnosed():
    plc = plcrt.load(program(counter(9, pv=100)))
    plc.scan()
    plc["I0.0"], plc["I0.1"] = 1, 1
    plc.scan()
    assert plc["HC0"] == 0
    assert any("A and B changed together" in d.message for d in plc.diagnostics)


def test_the_reset_input_clears_the_count_and_interrupts():
    """Mode 1: I0.2 resets (active high); event 28 external reset."""
    ob1 = counter(1, pv=100) + "\nATCH INT_0, 28"
    plc = plcrt.load(program(ob1, "LD SM0.0\nINCW VW0"))
    plc.scan()
    pulses(plc, "I0.0", 4)
    plc["I0.2"] = 1
    plc.scan()
    assert plc["HC0"] == 0 and plc["VW0"] == 1
    pulses(plc, "I0.0", 2)            # held in reset: no counting
    assert plc["HC0"] == 0
    plc["I0.2"] = 0
    plc.scan()
    pulses(plc, "I0.0", 2)
    assert plc["HC0"] == 2


def test_the_start_input_gates_counting():
    """HSC1 mode 2: clock I0.6, reset I1.0, start I1.1 (active high)."""
    plc = plcrt.load(program(counter(2, n=1, pv=100)))
    plc.scan()
    pulses(plc, "I0.6", 3)
    assert plc["HC1"] == 0
    plc["I1.1"] = 1
    plc.scan()
    pulses(plc, "I0.6", 3)
    assert plc["HC1"] == 3


def test_a_pto_wired_to_i0_0_is_counted_exactly_with_cv_pv_at_its_pulse():
    """The bench set-up: PLS Q0.0 -> HSC0 on I0.0.  PTO of 1000 pulses of
    100 µs from t = 0: pulse k rises at (k-1) x 100 µs, so CV = PV = 500 at
    49.9 ms, in the middle of a scan."""
    ob1 = (counter(0, pv=500) + "\nMOVB 16#85, SMB67\nMOVW +100, SMW68\nMOVD +1000, SMD72\n"
           "PLS 0")
    plc = plcrt.load(program(ob1, "LD SM0.0\nINCW VW0\nMOVD HC0, VD10"),
                     plant='[cpu]\nwire = { "I0.0" = "Q0.0" }\n')
    plc.scan()
    assert plc.hsc[0].next_time(0, 10**6) == 49_900
    plc.run("0.2s")
    assert (plc["VW0"], plc["VD10"], plc["HC0"]) == (1, 500, 1000)


def test_mode_12_counts_the_pulse_output_internally():
    ob1 = (counter(12, pv=250) + "\nMOVB 16#8D, SMB67\nMOVW +2, SMW68\nMOVD +300, SMD72\n"
           "PLS 0")
    plc = plcrt.load(program(ob1))
    plc.run("1s")
    assert (plc["VW0"], plc["VD10"], plc["HC0"]) == (1, 250, 300)


def test_hsc_updates_cv_pv_and_disables():
    ob1 = (counter(0, pv=100) + "\n\nLD M0.0\nEU\nMOVB 16#C0, SMB37\nMOVD +40, SMD38\nHSC 0\n\n"
           "LD M0.1\nEU\nMOVB 16#00, SMB37\nHSC 0")
    plc = plcrt.load(program(ob1))
    plc.scan()
    pulses(plc, "I0.0", 2)
    plc["M0.0"] = 1
    plc.scan()                      # CV := 40 (bit 6)
    pulses(plc, "I0.0", 1)
    assert plc["HC0"] == 41
    plc["M0.1"] = 1
    plc.scan()                      # disabled
    pulses(plc, "I0.0", 3)
    assert plc["HC0"] == 41


def test_hdef_twice_is_diagnosed_and_keeps_the_first_mode():
    plc = plcrt.load(program("LD SM0.0\nHDEF 0, 0"))
    plc.scan(2)
    assert plc.hsc[0].mode == 0
    assert any("HDEF of HSC0 executed again" in d.message for d in plc.diagnostics)


@pytest.mark.parametrize("ob1, message", [
    ("LD SM0.1\nHDEF 0, 2", "HSC0 mode 2 is not one of"),
    ("LD SM0.1\nHDEF 3, 1", "HSC3 mode 1 is not one of"),
    ("LD SM0.1\nHDEF 6, 0", "HSC 6 is not one of"),
    ("LD SM0.1\nHSC VB0", "HSC must be a constant"),
])
def test_what_the_cpu_refuses_is_a_compile_error(ob1, message):
    with pytest.raises(PlcCompileError) as e:
        plcrt.load(program(ob1))
    assert message in str(e.value)


@pytest.mark.parametrize("wire, message", [
    ('{ "I2.0" = "Q0.0" }', "inputs I0.0..I1.7"),
    ('{ "I0.0" = "Q2.0" }', "takes one of the CPU's outputs"),
    ('{ "Q0.0" = "Q0.1" }', "inputs I0.0..I1.7"),
])
def test_bad_wiring_in_the_plant_is_a_located_error(wire, message):
    with pytest.raises(PlcConfigError) as e:
        plcrt.load(program("LD SM0.0\n= Q0.2"), plant=f"[cpu]\nwire = {wire}\n")
    assert message in str(e.value) and "cpu.wire" in str(e.value)


def test_an_ordinary_output_wired_to_an_input_gives_edge_interrupts_next_scan():
    """Q0.5 wired to I0.0: the program's own output, copied to the terminal
    at the scan's end, is the input at the next scan start, where its edge
    interrupt (event 0) runs."""
    ob1 = "LD SM0.1\nATCH INT_0, 0\nENI\n\nLD M0.0\n= Q0.5"
    plc = plcrt.load(program(ob1, "LD SM0.0\nINCW VW0"),
                     plant='[cpu]\nwire = { "I0.0" = "Q0.5" }\n')
    plc.scan()
    plc["M0.0"] = 1
    plc.scan()                      # Q0.5 on at this scan's end
    assert plc["VW0"] == 0 and plc["I0.0"] == 0
    plc.scan()                      # the edge, at this scan's start
    assert plc["VW0"] == 1 and plc["I0.0"] == 1


ENCODER = """
[[cpu.encoder]]
inputs = ["I0.0", "I0.1"]
hz = 1000
start = 0.1
stop = 0.5
direction = "{direction}"
"""


@pytest.mark.parametrize("mode, control, direction, expected", [
    (0, "16#F8", "up", 401),     # one clock edge per cycle from 0.1 s to 0.5 s
    (9, "16#F8", "up", 1601),    # quadrature x4: four edges per cycle
    (9, "16#FC", "up", 401),     # quadrature x1
    (9, "16#F8", "down", -1601),
])
def test_an_encoder_of_the_plant_is_counted_in_closed_form(mode, control, direction, expected):
    plc = plcrt.load(program(counter(mode, control, pv=10**6)),
                     plant=ENCODER.format(direction=direction))
    plc.run("1s")
    assert plc["HC0"] == expected


def test_cv_pv_from_an_encoder_comes_at_its_exact_edge():
    """1000 Hz from 0.1 s, mode 0: edge k at 0.1 s + (k-1) ms; PV 250 at 0.349 s."""
    plc = plcrt.load(program(counter(0, pv=250)), plant=ENCODER.format(direction="up"))
    plc.scan()
    assert plc.hsc[0].next_time(plc.now_us, 10**7) == 349_000
    plc.run("1s")
    assert (plc["VW0"], plc["VD10"]) == (1, 250)


@pytest.mark.parametrize("encoder, message", [
    ('inputs = ["I0.0"]\nhz = 0', "hz must be a whole number"),
    ('inputs = ["I5.0"]\nhz = 10', "is not one of the CPU's inputs"),
    ('inputs = ["I0.0"]\nhz = 10\nstart = 2\nstop = 1', "stop is before start"),
    ('inputs = ["I0.0"]\nhz = 10\ndirection = "left"', "direction must be"),
    ('inputs = ["I0.0"]\nhz = 10\nspeed = 1', "unknown key(s) speed"),
    ('inputs = ["I0.0"]\nhz = 10\nstop = 1.8e302', "stop must be seconds"),
])
def test_bad_encoders_are_located_errors(encoder, message):
    with pytest.raises(PlcConfigError) as e:
        plcrt.load(program("LD SM0.0\n= Q0.2"), plant=f"[[cpu.encoder]]\n{encoder}\n")
    assert message in str(e.value) and "cpu.encoder[0]" in str(e.value)


def _steps(plc, *states):
    """Set HSC1's inputs (clock/up/A, dir/down/B) scan by scan."""
    for a, b in states:
        plc["I0.6"], plc["I0.7"] = a, b
        plc.scan()


@pytest.mark.parametrize("mode", range(12))
def test_every_mode_of_hsc1_counts_resets_and_starts_as_its_family(mode):
    """HSC1 has every mode 0..11 (I0.6, I0.7, reset I1.0, start I1.1).  One
    table: four counting steps up, then the reset input (modes 1, 2, 4, 5,
    7, 8, 10, 11) clears, and the start input (2, 5, 8, 11) gates."""
    family, extra = mode // 3, mode % 3
    plc = plcrt.load(program(counter(mode, n=1, pv=10**6)))
    if extra == 2:
        plc["I1.1"] = 1                  # start active, or nothing counts
    plc.scan()
    up = {0: [(1, 0), (0, 0)] * 4,                      # clock, direction bit up
          1: [(0, 1)] + [(1, 1), (0, 1)] * 4,          # clock, direction input high
          2: [(1, 0), (0, 0)] * 4,                      # up clock
          3: [(1, 0), (1, 1), (0, 1), (0, 0)]}[family]  # one A/B cycle: 4 at x4
    _steps(plc, *up)
    assert plc["HC1"] == 4
    if extra >= 1:
        plc["I1.0"] = 1
        plc.scan()
        assert plc["HC1"] == 0
        plc["I1.0"] = 0
        plc.scan()
    if extra == 2:
        plc["I1.1"] = 0
        plc.scan()
        _steps(plc, *up)
        assert plc["HC1"] == 0             # start inactive: no counting


def test_a_multi_segment_pto_wired_to_hsc0_reaches_pv_at_its_exact_pulse():
    """Segment 0: 100 pulses from 1000 µs down by 5 µs per pulse; segment 1:
    200 pulses of 500 µs.  PV = 150 is pulse 50 of segment 1: it rises at
    (100·1000 − 5·100·99/2) + 49·500 = 75 250 + 24 500 = 99 750 µs."""
    ob1 = (counter(0, pv=150) + "\nMOVB 2, VB500\n"
           "MOVW +1000, VW501\nMOVW -5, VW503\nMOVD +100, VD505\n"
           "MOVW +500, VW509\nMOVW +0, VW511\nMOVD +200, VD513\n"
           "MOVB 16#A5, SMB67\nMOVW +500, SMW168\nPLS 0")
    plc = plcrt.load(program(ob1, "LD SM0.0\nINCW VW0\nMOVD HC0, VD10"),
                     plant='[cpu]\nwire = { "I0.0" = "Q0.0" }\n', scan_ms=1)
    plc.scan()
    assert plc.hsc[0].next_time(plc.now_us, 10**7) == 99_750
    plc.run("0.2s")
    assert (plc["VW0"], plc["VD10"], plc["HC0"]) == (1, 150, 300)


from hypothesis import given, settings, strategies as st  # noqa: E402


@settings(max_examples=40, deadline=None)
@given(count=st.integers(1, 3000), cycle=st.integers(50, 2000),
       scan_ms=st.sampled_from([1, 2.5, 7, 10, 20]), data=st.data())
def test_property_a_wired_pto_is_counted_exactly_and_pv_comes_at_its_pulse(count, cycle,
                                                                            scan_ms, data):
    """For any train and scan time: HC0 ends at the pulse count, and the
    CV=PV routine runs once, at pulse PV's rising edge, (PV − 1) × cycle."""
    pv = data.draw(st.integers(1, count))
    ob1 = (counter(0, pv=pv) + f"\nMOVB 16#85, SMB67\nMOVW +{cycle}, SMW68\n"
           f"MOVD +{count}, SMD72\nPLS 0")
    plc = plcrt.load(program(ob1, "LD SM0.0\nINCW VW0\nMOVD HC0, VD10"),
                     plant='[cpu]\nwire = { "I0.0" = "Q0.0" }\n', scan_ms=scan_ms)
    plc.scan()
    assert plc.hsc[0].next_time(0, 10**9) in (None, (pv - 1) * cycle)
    plc.run((count * cycle) / 1e6 + 0.05)
    assert (plc["VW0"], plc["VD10"], plc["HC0"]) == (1, pv, count)
