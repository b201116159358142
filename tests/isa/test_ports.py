"""Freeport communication: XMT and RCV on the CPU's ports (plcrt.engine.ports;
S7-200 System Manual, "Communications instructions" and "Freeport mode").

Times are analytic: a character is 1 start + 7/8 data + 0/1 parity + 1
stop bits; k characters sent from t end at t + ceil(k x bits x 10^6 / baud)
µs (docs/decisions.md, "Communication ports").  The routines' run times are
recorded by wrapping the interrupt system's routine runner.
"""

from __future__ import annotations

import pytest

import plcrt
from plcrt.engine.serial import framing_of
from plcrt.errors import PlcCompileError, PlcConfigError


def program(ob1: str, *ints: str) -> str:
    """OB1 (networks separated by blank lines) and INT0, INT1, ... bodies."""
    out = ["ORGANIZATION_BLOCK MAIN:OB1", "BEGIN"]
    for i, net in enumerate(ob1.strip().split("\n\n"), 1):
        out += [f"Network {i}", *(ln.strip() for ln in net.strip().splitlines())]
    out.append("END_ORGANIZATION_BLOCK")
    for k, body in enumerate(ints):
        out += [f"INTERRUPT_BLOCK INT_{k}:INT{k}", "BEGIN", "Network 1",
                *(ln.strip() for ln in body.strip().splitlines()), "END_INTERRUPT_BLOCK"]
    return "\n".join(out) + "\n"


def record(plc: plcrt.Plc) -> list[tuple[int, int]]:
    """(INT number, µs) of every routine run from now on."""
    runs: list[tuple[int, int]] = []
    run = plc.interrupts.run_routine

    def spy(number: int) -> None:
        runs.append((number, plc._irq_t))
        run(number)

    plc.interrupts.run_routine = spy
    return runs


def end(t0: int, chars: int, bits: int, baud: int) -> int:
    return t0 + -(-chars * bits * 1_000_000 // baud)


COUNT = "LD SM0.0\nINCW VW0"


# ---------------------------------------------------------------- framing
@pytest.mark.parametrize("control, baud, data_bits, parity, protocol, bits", [
    (0x09, 9600, 8, "none", "freeport", 10),       # pp=00 d=0 bbb=010 mm=01
    (0x49, 9600, 8, "even", "freeport", 11),       # pp=01: even parity
    (0x89, 9600, 8, "none", "freeport", 10),       # pp=10: no parity
    (0xC9, 9600, 8, "odd", "freeport", 11),        # pp=11: odd parity
    (0x29, 9600, 7, "none", "freeport", 9),        # d=1: 7 data bits
    (0x69, 9600, 7, "even", "freeport", 10),
    (0x01, 38400, 8, "none", "freeport", 10), (0x05, 19200, 8, "none", "freeport", 10),
    (0x0D, 4800, 8, "none", "freeport", 10), (0x11, 2400, 8, "none", "freeport", 10),
    (0x15, 1200, 8, "none", "freeport", 10), (0x19, 115200, 8, "none", "freeport", 10),
    (0x1D, 57600, 8, "none", "freeport", 10),
    (0x08, 9600, 8, "none", "PPI slave", 10), (0x0A, 9600, 8, "none", "PPI master", 10),
    (0x0B, 9600, 8, "none", "PPI slave", 10),      # mm=11 reserved: PPI slave
])
def test_smb30_selects_the_framing_of_the_manuals_table(control, baud, data_bits, parity,
                                                       protocol, bits):
    fr = framing_of(control)
    assert (fr.baud, fr.data_bits, fr.parity, fr.protocol, fr.bits) == \
        (baud, data_bits, parity, protocol, bits)


def xmt_program(control: str, count: int, port: int = 0) -> str:
    smb = "SMB30" if port == 0 else "SMB130"
    event = 9 if port == 0 else 26
    return program(f"LD SM0.1\nMOVB {control}, {smb}\nMOVB {count}, VB100\n"
                   f"FILL 16#4142, VW101, 8\nATCH INT_0, {event}\nENI\nXMT VB100, {port}\n"
                   f"AENO\n= M0.0\n\nLD SM0.0\nMOVB SMB4, VB20", COUNT)


@pytest.mark.parametrize("control, bits, baud", [
    ("16#09", 10, 9600), ("16#05", 10, 19200), ("16#49", 11, 9600), ("16#45", 11, 19200),
    ("16#29", 9, 9600), ("16#19", 10, 115200),
])
@pytest.mark.parametrize("port", [0, 1])
def test_a_10_byte_xmt_completes_when_its_last_stop_bit_ends(control, bits, baud, port):
    """10 characters from t = 0: the transmit-complete event (9 / 26) runs
    its routine at ceil(10 x bits / baud) µs: 10417 µs at 9600 8N1, 5209 µs
    at 19200; the transmitter-idle bit SM4.5 / SM4.6 is 0 until then."""
    plc = plcrt.load(xmt_program(control, 10, port), scan_ms=1)
    runs = record(plc)
    plc.scan()
    idle = 0x20 if port == 0 else 0x40
    assert plc["M0.0"] == 1 and plc["VB20"] & idle == 0
    plc.run(0.03)
    assert runs == [(0, end(0, 10, bits, baud))]
    assert plc["VB20"] & idle == idle
    sent = plc.ports[0].unanswered[0][1] if port == 0 else plc.ports[1].unanswered[0][1]
    mask = 0x7F if bits == 9 else 0xFF
    assert sent == bytes(b & mask for b in b"ABABABABAB")


def test_the_two_event_times_at_9600_and_19200_baud():
    """The numbers the manual's rates give: 10 x 10 bits at 9600 baud is
    10416.67 µs (event at 10417), at 19200 baud 5208.33 µs (5209)."""
    for control, expected in (("16#09", 10417), ("16#05", 5209)):
        plc = plcrt.load(xmt_program(control, 10), scan_ms=1)
        runs = record(plc)
        plc.run(0.02)
        assert runs == [(0, expected)]


def test_a_count_of_zero_sends_a_break_of_16_bit_times():
    plc = plcrt.load(xmt_program("16#09", 0), scan_ms=1)
    runs = record(plc)
    plc.run(0.01)
    assert runs == [(0, end(0, 1, 16, 9600))]       # 1666.67 -> 1667 µs
    assert plc.ports[0].unanswered == []


def test_xmt_in_ppi_mode_is_refused_with_eno_0():
    """SMB30 = 16#08 selects PPI slave: XMT sends nothing, ENO 0, no event."""
    plc = plcrt.load(xmt_program("16#08", 4), scan_ms=1)
    runs = record(plc)
    plc.run(0.02)
    assert plc["M0.0"] == 0 and runs == [] and plc.ports[0].sent == 0
    assert any("PPI slave mode, not freeport" in d.message for d in plc.diagnostics)


def test_xmt_while_the_port_transmits_is_error_0009():
    """A second XMT before the first ended: ENO 0, SM4.3, nothing sent."""
    src = program("LD SM0.1\nMOVB 16#09, SMB30\nMOVB 4, VB100\nXMT VB100, 0\n\n"
                  "LD SM0.0\nXMT VB100, 0\nAENO\n= M0.0")
    plc = plcrt.load(src, scan_ms=1)
    plc.scan()
    assert plc["M0.0"] == 0 and plc["SM4.3"] == 1 and plc.ports[0].sent == 4
    assert any("error 0009" in d.message for d in plc.diagnostics)
    plc.run(0.01)                    # 4 characters take 4167 µs: then it may send
    assert plc["M0.0"] == 1 and plc.ports[0].sent > 4


def test_port_1_is_a_compile_error_on_a_one_port_cpu():
    with pytest.raises(PlcCompileError, match="port 0 only"):
        plcrt.load(program("LD SM0.0\nXMT VB100, 1"), cpu="CPU224")


@pytest.mark.parametrize("operand", ["AC0", "VW100", "T37", "LB0"])
def test_the_table_must_be_a_byte_address(operand):
    with pytest.raises(PlcCompileError, match="XMT: TBL must be a byte address"):
        plcrt.load(program(f"LD SM0.0\nXMT {operand}, 0"))


def test_an_indirect_table_is_read_through_its_pointer():
    src = program("LD SM0.1\nMOVB 16#09, SMB30\nMOVD &VB300, VD50\nMOVB 2, VB300\n"
                  "MOVW 16#1234, VW301\nXMT *VD50, 0")
    plc = plcrt.load(src)
    plc.scan()
    assert plc.ports[0].unanswered[0][1] == b"\x12\x34"


# ---------------------------------------------------------------- RCV
MSG_DONE = "LD SM0.0\nINCW VW0\nMOVB SMB86, VB10"        # INT0 on event 23
CHAR = "LD SM0.0\nINCW VW2\nMOVB SMB2, VB12\nLD SM3.0\nS M1.0, 1"   # INT1 on event 8


def rcv_program(control: int, start: int = 0, stop: int = 0, idle_ms: int = 0,
                timer_ms: int = 0, max_count: int = 20, smb30: str = "16#09") -> str:
    return program(f"LD SM0.1\nMOVB {smb30}, SMB30\nMOVB 16#{control:02X}, SMB87\n"
                   f"MOVB 16#{start:02X}, SMB88\nMOVB 16#{stop:02X}, SMB89\n"
                   f"MOVW +{idle_ms}, SMW90\nMOVW +{timer_ms}, SMW92\nMOVB {max_count}, SMB94\n"
                   f"ATCH INT_0, 23\nATCH INT_1, 8\nENI\nRCV VB200, 0\nAENO\nS M0.0, 1",
                   MSG_DONE, CHAR)


def sends(*rows: tuple[float, str], bad: dict[int, list[int]] | None = None) -> str:
    """A plant whose port-0 device sends *rows* (time s, hex) unasked."""
    out = ["[port.0]"]
    for k, (at, data) in enumerate(rows):
        out += ["[[port.0.send]]", f"at = {at}", f'data = "{data}"']
        if bad and k in bad:
            out.append(f"bad_parity = {bad[k]}")
    return "\n".join(out) + "\n"


def received(plc: plcrt.Plc) -> bytes:
    n = plc["VB200"]
    return bytes(plc[f"VB{201 + k}"] for k in range(n))


EN, SC, EC, IL, CM, TMR, BK = 0x80, 0x40, 0x20, 0x10, 0x08, 0x04, 0x02


def test_start_and_end_character_frame_a_message():
    """sc and ec: characters before the start character are ignored; the
    message holds the start and end characters; it ends with SMB86 = 16#20
    (end character) when the end character's stop bit ends."""
    plc = plcrt.load(rcv_program(EN | SC | EC, start=0x02, stop=0x03),
                     plant=sends((0.01, "55 02 41 42 43 03 66")), scan_ms=1)
    runs = record(plc)
    plc.run(0.03)
    assert plc["M0.0"] == 1
    assert received(plc) == bytes.fromhex("02 41 42 43 03")
    assert plc["VB10"] == 0x20 and plc["VW0"] == 1
    assert (0, end(10_000, 6, 10, 9600)) in runs      # the 6th character is 03
    assert plc["VW2"] == 7                            # every character interrupts


def test_idle_line_the_first_character_after_the_idle_time_starts_the_message():
    """SMW90 = 5 ms: '11 22' at 1 ms keep the line busy (the idle time
    starts again after each); '33 44 55' at 20 ms follow 5 ms of quiet:
    they are the message, ended by the maximum count 3 (SMB86 = 16#02)."""
    plc = plcrt.load(rcv_program(EN | IL, idle_ms=5, max_count=3),
                     plant=sends((0.001, "11 22"), (0.020, "33 44 55")), scan_ms=1)
    runs = record(plc)
    plc.run(0.03)
    assert received(plc) == bytes.fromhex("33 44 55") and plc["VB10"] == 0x02
    assert (0, end(20_000, 3, 10, 9600)) in runs


def test_characters_within_the_idle_time_restart_it():
    """Characters 3 ms apart never leave the line idle for 5 ms: no message."""
    rows = [(0.001 + 0.003 * k, "AA") for k in range(8)]
    plc = plcrt.load(rcv_program(EN | IL, idle_ms=5, max_count=3), plant=sends(*rows),
                     scan_ms=1)
    plc.run(0.03)
    assert plc["VW0"] == 0 and plc["VB200"] == 0 and plc["VW2"] == 8


def test_the_inter_character_timer_ends_the_message():
    """Any character (il, SMW90 = 0) with a 5 ms inter-character timer: the
    message '01 02 03' ends 5 ms after the last stop bit (SMB86 = 16#04)."""
    plc = plcrt.load(rcv_program(EN | IL | TMR, timer_ms=5),
                     plant=sends((0.010, "01 02 03")), scan_ms=1)
    runs = record(plc)
    plc.run(0.05)
    assert received(plc) == bytes.fromhex("01 02 03") and plc["VB10"] == 0x04
    assert [r for r in runs if r[0] == 0] == [(0, end(10_000, 3, 10, 9600) + 5000)]


def test_the_message_timer_in_any_character_mode_runs_from_the_rcv():
    """c/m = 1: with nothing received the receive ends SMW92 = 20 ms after
    the RCV (the 'no answer' time-out), count 0."""
    plc = plcrt.load(rcv_program(EN | IL | CM | TMR, timer_ms=20), scan_ms=1)
    runs = record(plc)
    plc.run(0.05)
    assert runs == [(0, 20_000)] and plc["VB10"] == 0x04 and plc["VB200"] == 0


def test_the_message_timer_after_a_start_character_runs_from_the_message_start():
    """sc with a 10 ms message timer: the message starts with 02 at 5 ms
    (its stop bit ends at 5000 + 1042 µs); a long message is cut 10 ms
    later, whatever the gaps between characters."""
    rows = [(0.005, "02")] + [(0.0075 + 0.002 * k, "41") for k in range(10)]
    plc = plcrt.load(rcv_program(EN | SC | CM | TMR, start=0x02, timer_ms=10),
                     plant=sends(*rows), scan_ms=1)
    runs = record(plc)
    plc.run(0.05)
    t_start = end(5000, 1, 10, 9600)
    assert [r for r in runs if r[0] == 0] == [(0, t_start + 10_000)]
    # characters whose stop bit ended by then: 41 at 7.5, 9.5, 11.5, 13.5 ms (+1042)
    assert received(plc) == bytes.fromhex("02 41 41 41 41") and plc["VB10"] == 0x04


def test_a_break_starts_the_message():
    """bk: characters before a break are ignored; after it, the first
    character starts the message."""
    plc = plcrt.load(rcv_program(EN | BK, max_count=2),
                     plant=sends((0.002, "11"), (0.005, ""), (0.010, "21 22")), scan_ms=1)
    plc.run(0.03)
    assert received(plc) == bytes.fromhex("21 22") and plc["VB10"] == 0x02


def test_a_parity_error_ends_the_message_and_sets_sm3_0():
    """8E1 (SMB30 = 16#49): the second character arrives with a parity
    error: the character interrupt sees SM3.0 = 1, the receive ends with
    SMB86 = 16#01."""
    plc = plcrt.load(rcv_program(EN | IL, smb30="16#49"),
                     plant=sends((0.002, "10 20 30"), bad={0: [1]}), scan_ms=1)
    runs = record(plc)
    plc.run(0.03)
    assert plc["VB10"] == 0x01 and plc["M1.0"] == 1
    assert received(plc) == bytes.fromhex("10 20")
    assert (0, end(2000, 2, 11, 9600)) in runs


def test_rcv_with_the_enable_bit_0_ends_a_receive_by_user_disable():
    src = program("LD SM0.1\nMOVB 16#09, SMB30\nMOVB 16#90, SMB87\nMOVW +0, SMW90\n"
                  "MOVB 10, SMB94\nATCH INT_0, 23\nENI\nRCV VB200, 0\n\n"
                  "LD I0.0\nEU\nMOVB 16#00, SMB87\nRCV VB200, 0", MSG_DONE)
    plc = plcrt.load(src, scan_ms=1)
    plc.run(0.005)
    assert plc["VW0"] == 0
    plc["I0.0"] = 1
    plc.scan()
    assert plc["VW0"] == 1 and plc["VB10"] == 0x80


@pytest.mark.parametrize("control, max_count, timer, why", [
    (EN | IL, 0, 0, "maximum character count"),
    (EN | EC, 10, 0, "no start condition"),
    (EN | IL | BK, 10, 0, "idle line and break"),
    (EN | IL | TMR, 10, 0, "timer is enabled with SMW92 = 0"),
])
def test_a_receive_parameter_error_sets_smb86_6(control, max_count, timer, why):
    plc = plcrt.load(rcv_program(control, max_count=max_count, timer_ms=timer), scan_ms=1)
    plc.scan()
    assert plc["M0.0"] == 0 and plc["VB10"] == 0x40 and plc["VW0"] == 1
    assert any(why in d.message for d in plc.diagnostics)


def test_seven_data_bits_drop_the_top_bit():
    plc = plcrt.load(rcv_program(EN | IL, max_count=2, smb30="16#29"),
                     plant=sends((0.002, "C1 42")), scan_ms=1)
    plc.run(0.02)
    assert received(plc) == bytes.fromhex("41 42")


def test_characters_to_a_port_in_ppi_mode_are_ignored():
    plc = plcrt.load(rcv_program(EN | IL, smb30="16#08"), plant=sends((0.002, "41")),
                     scan_ms=1)
    plc.run(0.02)
    assert plc["VW2"] == 0 and plc["M0.0"] == 0


def test_a_break_keeps_the_line_busy_for_the_idle_line_condition():
    """SMW90 = 5 ms: a break ending at 4 ms restarts the idle time, so '33'
    at 7 ms is not yet a message start; '44' at 15 ms is."""
    plc = plcrt.load(rcv_program(EN | IL, idle_ms=5, max_count=1),
                     plant=sends((0.0023, ""), (0.007, "33"), (0.015, "44")), scan_ms=1)
    plc.run(0.03)
    assert received(plc) == bytes.fromhex("44") and plc["VB10"] == 0x02


def test_every_character_interrupts_with_smb2_at_its_stop_bit():
    """Event 8 without RCV: each character's routine runs when its stop bit
    ends, with the character in SMB2 (the routine stores them through a
    pointer); port 1's characters use event 25 and the same SMB2."""
    src = program("LD SM0.1\nMOVB 16#09, SMB30\nMOVB 16#05, SMB130\nMOVD &VB300, VD50\n"
                  "ATCH INT_0, 8\nATCH INT_0, 25\nENI",
                  "LD SM0.0\nMOVB SMB2, *VD50\nINCD VD50")
    plant = sends((0.001, "31 32 33")) + "[port.1]\n[[port.1.send]]\nat = 0.010\ndata = \"7E\"\n"
    plc = plcrt.load(src, plant=plant, scan_ms=1)
    runs = record(plc)
    plc.run(0.02)
    assert runs == [(0, end(1000, k, 10, 9600)) for k in (1, 2, 3)] + \
        [(0, end(10_000, 1, 10, 19200))]
    assert bytes(plc[f"VB{300 + k}"] for k in range(4)) == b"123~"


@pytest.mark.parametrize("insn", ["XMT *VD50, 0", "RCV *VD50, 0", "NETR *VD50, 0",
                                  "GET *VD50"])
def test_a_pointer_to_no_table_area_gives_eno_0(insn):
    """A pointer to T memory (area code 9) or past the end of V names no
    table: nothing is done, ENO 0, and the diagnostics say so."""
    for ptr in ("16#09000000", "16#08002800"):
        src = program(f"LD SM0.1\nMOVB 16#09, SMB30\nMOVB 16#90, SMB87\nMOVB 5, SMB94\n"
                      f"MOVD {ptr}, VD50\n{insn}\nAENO\n= M0.0")
        plc = plcrt.load(src)
        plc.scan()
        assert plc["M0.0"] == 0
        assert any("16#" + ptr[3:] in d.message and "ENO = 0" in d.message
                   for d in plc.diagnostics), [d.message for d in plc.diagnostics]


def test_the_port_is_half_duplex():
    """XMT while the port's receive runs, and RCV while it transmits, are the
    manual's 'simultaneous XMT/RCV' (error 0009): ENO 0, SM4.3."""
    src = program("LD SM0.1\nMOVB 16#09, SMB30\nMOVB 16#90, SMB87\nMOVW +0, SMW90\n"
                  "MOVB 10, SMB94\nMOVB 2, VB100\nRCV VB200, 0\nXMT VB100, 0\nAENO\n"
                  "S M0.0, 1\n\nLD I0.0\nMOVB 16#10, SMB87\nRCV VB200, 0\nMOVB 16#90, SMB87\n"
                  "XMT VB100, 0\nRCV VB200, 0\nAENO\nS M0.1, 1")
    plc = plcrt.load(src, scan_ms=1)
    plc.scan()
    assert plc["M0.0"] == 0 and plc["SM4.3"] == 1 and plc.ports[0].sent == 0
    assert any("while a receive (RCV) is still running: error 0009" in d.message
               for d in plc.diagnostics)
    plc["I0.0"] = 1                      # end the receive, send, then RCV: refused
    plc.scan()
    assert plc.ports[0].sent == 2 and plc["M0.1"] == 0 and plc.ports[0].rx is None
    assert any("while a transmission is still running" in d.message for d in plc.diagnostics)
