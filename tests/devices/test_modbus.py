"""The Modbus RTU master library (MBUS_CTRL, MBUS_MSG) against the plant's
Modbus RTU slave over the port's exact-timed serial model
(plcrt.devices.modbus; docs/modbus.md).

Times: k characters of b bits at B baud sent from t end at
t + ceil(k * b * 10^6 / B) µs; a frame is known ended 3.5 characters after
its last stop bit (ceil(7 * b * 10^6 / 2B) µs at 19200 baud and below).
"""

from __future__ import annotations

import pytest

import plcrt
from plcrt.devices.modbus.master import master_of
from plcrt.devices.modbus.rtu import crc16, frame, gap_us, pack_bits, unpack_bits
from plcrt.devices.plant import load_plant
from plcrt.errors import PlcConfigError

#: OB1: MBUS_CTRL and MBUS_MSG with every input in V memory, so that each
#: test sets them: Mode M0.0, Baud VD200, Parity VB204, Timeout VW206;
#: First M2.0, Slave VB210, RW VB211, Addr VD212, Count VW216, DataPtr VD218
PROGRAM = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     SM0.0
CALL   MBUS_CTRL, M0.0, VD200, VB204, VW206, M0.1, MB1
Network 2
LD     SM0.0
CALL   MBUS_MSG, M2.0, VB210, VB211, VD212, VW216, VD218, M0.2, MB3
END_ORGANIZATION_BLOCK
"""
V = 0x08000000   #: pointer to VB0 (&VB0)


def slave(**tables) -> str:
    body = {"address": 1, "holding_registers": [42, 7, 9, 1000],
            "coils": [1, 0, 1, 1, 0, 0, 0, 0, 1, 1], "input_registers": [300, 301],
            "discrete_inputs": [0, 1, 1]}
    body.update(tables)
    lines = ["[port.0.modbus_slave]"]
    for k, v in body.items():
        lines.append(f"{k} = {str(v).lower() if isinstance(v, bool) else v}")
    return "\n".join(lines) + "\n"


def load(plant: str = "", baud: int = 9600, parity: int = 0, timeout: int = 100,
         program: str = PROGRAM, **kw) -> plcrt.Plc:
    plc = plcrt.load(program, plant=load_plant(plant) if plant else None, scan_ms=1, **kw)
    plc["M0.0"] = 1
    plc["VD200"], plc["VB204"], plc["VW206"] = baud, parity, timeout
    plc.scan()
    return plc


def msg(plc: plcrt.Plc, slave_addr: int, rw: int, addr: int, count: int, vb: int = 100,
        scans: int = 200) -> dict:
    """One MBUS_MSG request (First for one scan); scans until Done; the
    master's record of it (µs) with Done and Error as the program saw them."""
    plc["VB210"], plc["VB211"], plc["VD212"], plc["VW216"] = slave_addr, rw, addr, count
    plc["VD218"] = V + vb
    plc["M2.0"] = 1
    plc.scan()
    plc["M2.0"] = 0
    log = master_of(plc).log
    before = len(log)
    for _ in range(scans):
        if plc["M0.2"]:
            break
        plc.scan()
    out = dict(log[-1]) if len(log) > before else {}
    out.update(done=plc["M0.2"], error=plc["MB3"], seen=plc.now_us)
    return out


# ---------------------------------------------------------------- frames
def test_crc_of_a_known_request():
    """The CRC of read 2 holding registers at 0 from slave 1 is C4 0B (low byte first)."""
    assert frame(bytes.fromhex("010300000002")).hex() == "010300000002c40b"
    assert crc16(b"") == 0xFFFF


def test_bits_pack_lsb_first():
    """Bit 0 is the least significant bit of the first byte."""
    assert pack_bits([1, 0, 1, 1, 0, 0, 0, 0, 1]) == bytes((0x0D, 0x01))
    assert unpack_bits(bytes((0x0D, 0x01)), 9) == [1, 0, 1, 1, 0, 0, 0, 0, 1]


def test_gap_is_three_and_a_half_characters():
    """3.5 characters up to 19200 baud, 1750 µs above."""
    assert gap_us(10, 9600) == 3646 and gap_us(10, 19200) == 1823
    assert gap_us(11, 9600) == 4011 and gap_us(10, 38400) == 1750


# ---------------------------------------------------------------- MBUS_CTRL
def test_ctrl_takes_the_port_and_gives_it_back():
    """Mode 1 sets SMB30 to freeport at the baud and parity; Mode 0 back to PPI."""
    plc = load(slave(), baud=19200, parity=2)
    assert plc["SMB30"] == 0x45 and plc["M0.1"] == 1 and plc["MB1"] == 0
    plc["M0.0"] = 0
    plc.scan()
    assert plc["SMB30"] == 0x00 and plc.ports[0].owner is None


@pytest.mark.parametrize("baud, parity, timeout, error", [
    (9600, 3, 100, 1), (9601, 0, 100, 2), (9600, 0, 0, 3), (9600, 0, -5, 3)])
def test_ctrl_parameter_errors(baud, parity, timeout, error):
    """Parity not 0..2 is Error 1, a baud rate not in the table 2, Timeout not 1..32767 3."""
    plc = load(slave(), baud=baud, parity=parity, timeout=timeout)
    assert (plc["M0.1"], plc["MB1"]) == (1, error)
    assert plc["SMB30"] == 0
    r = msg(plc, 1, 0, 40001, 1)
    assert (r["done"], r["error"]) == (1, 5)      # master not enabled


SMART_CTRL = PROGRAM.replace("CALL   MBUS_CTRL, M0.0, VD200, VB204, VW206",
                             "CALL   MBUS_CTRL, M0.0, VD200, VB204, VB205, VW206")


@pytest.mark.parametrize("cpu, port, error", [("CPU226", 1, 0), ("CPU226", 2, 9),
                                              ("CPU224", 1, 10)])
def test_smart_ctrl_port_input(cpu, port, error):
    """The SMART MBUS_CTRL (a Port input): port 1 is SMB130; no port 2 (Error 9);
    port 1 of a one-port CPU is Error 10."""
    plc = plcrt.load(SMART_CTRL, scan_ms=1, cpu=cpu)
    plc["M0.0"], plc["VD200"], plc["VB205"], plc["VW206"] = 1, 9600, port, 100
    plc.scan()
    assert plc["MB1"] == error
    if not error:
        assert plc["SMB130"] == 0x09 and plc.ports[1].owner is master_of(plc)


# ---------------------------------------------------------------- reads
def test_read_holding_registers_exact_times_9600():
    """Read 2 holding registers: the 8-byte request from the scan's start
    (1000 µs) ends 8334 µs later; the slave knows it ended 3646 µs after,
    answers 9 bytes (9375 µs), and the master has the response 3646 µs
    after its last stop bit; the next scan's MBUS_MSG shows Done."""
    plc = load(slave())
    r = msg(plc, 1, 0, 40001, 2)
    assert (r["done"], r["error"]) == (1, 0)
    assert (plc["VW100"], plc["VW102"]) == (42, 7)
    assert r["sent"] == 1000 and r["sent_end"] == 9334
    assert r["first_char"] == 9334 + 3646 + 1042
    assert r["last_char"] == 9334 + 3646 + 9375
    assert r["done"] and master_of(plc).log[-1]["finished"] == 22355 + 3646
    # the scan from 27 000 µs (the first after 26 001) shows Done; now_us is its end
    assert r["seen"] == 28000
    assert plc.ports[0].peer.requests[-1][1] == bytes.fromhex("010300000002c40b")


def test_read_times_at_19200_and_slave_delay():
    """At 19200 baud the same exchange halves; the slave's delay_ms comes
    after the request's gap."""
    plc = load(slave(delay_ms=2), baud=19200)
    r = msg(plc, 1, 0, 40002, 3)
    assert (plc["VW100"], plc["VW102"], plc["VW104"]) == (7, 9, 1000)
    start = 1000 + 4167 + 1823 + 2000
    assert r["sent_end"] == 5167 and r["first_char"] == start + 521
    assert r["last_char"] == start + 5730          # 11 bytes: 110 bits
    assert master_of(plc).log[-1]["finished"] == start + 5730 + 1823


def test_read_with_even_parity_takes_eleven_bits():
    """Parity 2 (even): 11 bits a character, at both ends."""
    plc = load(slave(), parity=2)
    r = msg(plc, 1, 0, 30001, 2)
    assert (plc["VW100"], plc["VW102"]) == (300, 301) and r["error"] == 0
    assert r["sent_end"] == 1000 + 9167


def test_read_coils_and_inputs_pack_into_bytes():
    """10 coils from 00001 arrive as 2 bytes, the first coil in bit 0 of
    VB100; 3 discrete inputs from 10001 in VB102."""
    plc = load(slave())
    assert msg(plc, 1, 0, 1, 10)["error"] == 0
    assert (plc["VB100"], plc["VB101"]) == (0x0D, 0x03)
    assert msg(plc, 1, 0, 10001, 3, vb=102)["error"] == 0
    assert plc["VB102"] == 0x06


# ---------------------------------------------------------------- writes
def test_write_one_register_uses_function_6():
    """RW 1, Count 1 at 40003: function 6 with VW100; the slave's register changes."""
    plc = load(slave())
    plc["VW100"] = 4321
    r = msg(plc, 1, 1, 40003, 1)
    assert (r["done"], r["error"]) == (1, 0)
    assert plc.ports[0].peer.holding[2] == 4321
    assert plc.ports[0].peer.requests[-1][1] == frame(bytes.fromhex("0106000210E1"))


def test_write_registers_uses_function_16():
    plc = load(slave())
    plc["VW100"], plc["VW102"] = 11, 12
    assert msg(plc, 1, 1, 40002, 2)["error"] == 0
    assert plc.ports[0].peer.holding[:4] == [42, 11, 12, 1000]
    assert plc.ports[0].peer.requests[-1][1][1] == 16


def test_write_coils_functions_5_and_15():
    """One coil: function 5 (FF00 on); nine coils: function 15 from the bytes at DataPtr."""
    plc = load(slave())
    plc["VB100"] = 0x01
    assert msg(plc, 1, 1, 2, 1)["error"] == 0
    assert plc.ports[0].peer.coils[1] == 1
    assert plc.ports[0].peer.requests[-1][1] == frame(bytes.fromhex("01050001FF00"))
    plc["VB100"], plc["VB101"] = 0xF0, 0xFF      # bits past Count go as 0
    assert msg(plc, 1, 1, 1, 9)["error"] == 0
    assert plc.ports[0].peer.coils == [0, 0, 0, 0, 1, 1, 1, 1, 1, 1]
    assert plc.ports[0].peer.requests[-1][1][:9] == bytes.fromhex("010F00000009 02F001")


def test_broadcast_write_gets_no_answer():
    """Slave 0 writes to every slave; Done when the request and its gap have passed."""
    plc = load(slave())
    plc["VW100"] = 5
    r = msg(plc, 0, 1, 40001, 1)
    assert (r["done"], r["error"]) == (1, 0) and r["done"]
    assert master_of(plc).log[-1]["finished"] == 9334 + 3646
    assert plc.ports[0].peer.holding[0] == 5


# ---------------------------------------------------------------- errors
def test_no_answer_is_receive_timeout():
    """Slave 9 is not there: Error 3, Timeout ms after the request's end."""
    plc = load(slave(), timeout=50)
    r = msg(plc, 9, 0, 40001, 1)
    assert (r["done"], r["error"]) == (1, 3)
    assert master_of(plc).log[-1]["finished"] == 9334 + 50_000


def test_exception_from_the_slave():
    """Registers past the slave's table: exception 2, Error 102; nothing is copied."""
    plc = load(slave())
    plc["VW100"] = 77
    r = msg(plc, 1, 0, 40003, 5)
    assert (r["done"], r["error"]) == (1, 102) and plc["VW100"] == 77
    assert any("Error 102" in d.message for d in plc.diagnostics)


def scripted(reply: str) -> str:
    return f'[[port.0.reply]]\nrequest = "01 03 00 00 00 01 84 0A"\nreply = "{reply}"\n'


@pytest.mark.parametrize("reply, error", [
    ("01 03 02 00 2A 00 00", 8),               # a wrong CRC
    (frame(bytes.fromhex("0203 02 002A")).hex(" "), 7),    # another slave answered
    (frame(bytes.fromhex("0104 02 002A")).hex(" "), 7),    # another function
    (frame(bytes.fromhex("0103 04 002A0000")).hex(" "), 7),  # too many bytes
    (frame(bytes.fromhex("0183 04")).hex(" "), 104),       # exception 4
    (frame(bytes.fromhex("0183 07")).hex(" "), 107),       # another exception code
])
def test_bad_responses(reply, error):
    """The response is checked: CRC (8), slave, function and length (7), exceptions."""
    plc = load(scripted(reply))
    plc["VW100"] = 5
    r = msg(plc, 1, 0, 40001, 1)
    assert (r["done"], r["error"]) == (1, error) and plc["VW100"] == 5


def test_a_good_scripted_response():
    """The same scripted device with a right answer: the register arrives
    (the checks above can pass)."""
    plc = load(scripted(frame(bytes.fromhex("0103 02 002A")).hex(" ")))
    assert msg(plc, 1, 0, 40001, 1)["error"] == 0 and plc["VW100"] == 42


def test_parity_error_in_response():
    """A character of the response with a parity error: Error 1."""
    plant = scripted(frame(bytes.fromhex("0103 02 002A")).hex(" ")) + "bad_parity = [3]\n"
    plc = load(plant, parity=2)
    assert msg(plc, 1, 0, 40001, 1)["error"] == 1


@pytest.mark.parametrize("slave_addr, rw, addr, count", [
    (248, 0, 40001, 1), (1, 2, 40001, 1), (1, 0, 20001, 1), (1, 0, 50000, 1),
    (1, 1, 30001, 1), (1, 1, 10001, 1), (0, 0, 40001, 1), (1, 0, 40001, 0),
    (1, 0, 40001, 121), (1, 0, 1, 1921), (1, 0, 49999, 2)])
def test_request_parameter_errors(slave_addr, rw, addr, count):
    """Slave, RW, Addr and Count outside the library's ranges: Error 4 at
    once, nothing sent."""
    plc = load(slave())
    sent = plc.ports[0].sent
    r = msg(plc, slave_addr, rw, addr, count, scans=1)
    assert (r["done"], r["error"]) == (1, 4) and plc.ports[0].sent == sent


def test_data_pointer_must_be_v_memory():
    plc = load(slave())
    plc["VB210"], plc["VB211"], plc["VD212"], plc["VW216"] = 1, 0, 40001, 1
    plc["VD218"] = 0x03000000          # &MB0
    plc["M2.0"] = 1
    plc.scan()
    assert (plc["M0.2"], plc["MB3"]) == (1, 4)


TWO = PROGRAM.replace("END_ORGANIZATION_BLOCK", """Network 3
LD     SM0.0
CALL   MBUS_MSG, M4.0, 1, 0, 40001, 1, &VB150, M4.1, MB5
END_ORGANIZATION_BLOCK""")


def test_second_request_while_busy_is_error_6():
    """Only one MBUS_MSG runs at a time: another site's First is Error 6;
    the running one finishes."""
    plc = load(slave(), program=TWO)
    plc["VB210"], plc["VB211"], plc["VD212"], plc["VW216"], plc["VD218"] = \
        1, 0, 40002, 1, V + 100
    plc["M2.0"] = 1
    plc["M4.0"] = 1
    plc.scan()
    plc["M2.0"] = plc["M4.0"] = 0
    assert (plc["M4.1"], plc["MB5"]) == (1, 6) and plc["M0.2"] == 0
    plc.run(scans=40)
    assert (plc["M0.2"], plc["MB3"], plc["VW100"]) == (1, 0, 7)


# ---------------------------------------------------------------- plant keys
@pytest.mark.parametrize("text, words", [
    ("[port.0.modbus_slave]\nadress = 1\n", "unknown key"),
    ("[port.0.modbus_slave]\naddress = 0\n", "1..247"),
    ("[port.0.modbus_slave]\nholding_registers = [70000]\n", "0..65535"),
    ("[port.0.modbus_slave]\ncoils = [2]\n", "0..1"),
    ('[port.0.modbus_slave]\n[[port.0.reply]]\nrequest = "01"\nreply = "02"\n',
     "one device per port")])
def test_plant_keys_are_checked(text, words):
    with pytest.raises(PlcConfigError, match=words):
        load_plant(text)


# ---------------------------------------------------------------- the export
def sbr(name: str, number: int, params: list[tuple[str, str]], body: str = "") -> str:
    out = [f"SUBROUTINE_BLOCK {name}:SBR{number}", "TITLE=library block"]
    for section in ("IN", "OUT"):
        decls = [(i, t) for i, (s, t) in enumerate(params) if s == section]
        if decls:
            out.append(f"VAR_{'INPUT' if section == 'IN' else 'OUTPUT'}")
            out += [f"p{i}:{t};" for i, t in decls]
            out.append("END_VAR")
    out.append("BEGIN")
    if body:
        out += ["Network 1", *body.splitlines()]
    out.append("END_SUBROUTINE_BLOCK")
    return "\n".join(out) + "\n"


CTRL_ITF = [("IN", "BOOL"), ("IN", "DWORD"), ("IN", "BYTE"), ("IN", "INT"), ("OUT", "BOOL"),
            ("OUT", "BYTE")]
MSG_ITF = [("IN", "BOOL"), ("IN", "BYTE"), ("IN", "BYTE"), ("IN", "DWORD"), ("IN", "INT"),
           ("IN", "DWORD"), ("OUT", "BOOL"), ("OUT", "BYTE")]
EXPORT_OB1 = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     SM0.0
CALL   SBR1, M0.0, VD200, VB204, VW206, M0.1, MB1
Network 2
LD     SM0.0
CALL   SBR2, M2.0, VB210, VB211, VD212, VW216, VD218, M0.2, MB3
Network 3
LD     SM0.1
CALL   SBR3, M6.0
END_ORGANIZATION_BLOCK
"""


def test_export_protected_blocks_run_the_library():
    """An export's MBUS_CTRL / MBUS_MSG (interface, empty body) run the
    library, with the load warning naming plcrt's error numbers; an empty
    MBUS_INIT with another interface than the slave library's runs as the
    program's own subroutine, with a warning."""
    text = EXPORT_OB1 + sbr("MBUS_CTRL", 1, CTRL_ITF) + sbr("MBUS_MSG", 2, MSG_ITF) \
        + sbr("MBUS_INIT", 3, [("IN", "BOOL")])
    plc = load(slave(), program=text)
    warns = [d.message for d in plc.diagnostics]
    assert sum("Modbus RTU master library" in w and "107" in w for w in warns) == 1
    assert any("MBUS_INIT" in w and "own subroutine runs" in w for w in warns)
    assert not any("MBUS_MSG" in w and "no code" in w for w in warns)
    r = msg(plc, 1, 0, 40001, 2)
    assert r["error"] == 0 and (plc["VW100"], plc["VW102"]) == (42, 7)


def test_export_block_with_code_or_other_interface_runs_its_own_code():
    """A MBUS_MSG with instructions, or a MBUS_CTRL with another interface,
    is the program's own subroutine, with a warning."""
    text = EXPORT_OB1.replace("Network 3\nLD     SM0.1\nCALL   SBR3, M6.0\n", "") \
        + sbr("MBUS_CTRL", 1, CTRL_ITF[:3] + [("IN", "WORD")] + CTRL_ITF[4:]) \
        + sbr("MBUS_MSG", 2, MSG_ITF, body="LD SM0.0\n= M9.0")
    plc = load(slave(), program=text)
    own = [d.message for d in plc.diagnostics if "own subroutine runs" in d.message]
    assert len(own) == 2 and any("IN WORD" in w for w in own)
    assert plc["SMB30"] == 0 and plc["M9.0"] == 1


# ---------------------------------------------------------------- the sample
def test_sample_poll_reads_and_writes_back():
    """programs/modbus/poll.awl: 12 read/write rounds in 1 s of 10 ms scans;
    the slave's 40005 holds VW100 + 1; the first read's times are exact
    (9600 baud, the slave's 5 ms delay)."""
    from pathlib import Path
    root = Path(__file__).resolve().parents[2] / "programs" / "modbus"
    plc = plcrt.load(root / "poll.awl", plant=root / "slave_plant.toml", scan_ms=10)
    plc.run(1.0)
    assert (plc["VW100"], plc["VW102"], plc["VW20"], plc["MB3"]) == (1200, 35, 12, 0)
    assert plc.ports[0].peer.holding[4] == 1201
    first = master_of(plc).log[0]
    assert (first["sent"], first["sent_end"]) == (0, 8334)
    assert first["last_char"] == 8334 + 3646 + 5000 + 13 * 10 * 1_000_000 // 9600 + 1


def test_a_fork_runs_on_with_its_own_master_and_slave():
    """A fork in the middle of a request finishes it on its own port and
    slave; the original is not affected."""
    plc = load(slave())
    plc["VW100"] = 99
    plc["VB210"], plc["VB211"], plc["VD212"], plc["VW216"], plc["VD218"] = \
        1, 1, 40001, 1, V + 100
    plc["M2.0"] = 1
    plc.scan(3)
    plc["M2.0"] = 0
    twin = plc.fork()
    assert master_of(twin).busy() and master_of(twin) is not master_of(plc)
    twin.run(scans=40)
    assert (twin["M0.2"], twin["MB3"]) == (1, 0) and twin.ports[0].peer.holding[0] == 99
    assert plc.ports[0].peer.holding[0] == 42 and plc["M0.2"] == 0


def test_slave_at_another_rate_never_answers():
    """A slave set to 19200 baud while the master sends at 9600 gets garbled
    characters: no answer, Error 3; at its own rate it answers."""
    plc = load(slave(baud=19200), timeout=30)
    assert msg(plc, 1, 0, 40001, 1)["error"] == 3 and plc.ports[0].peer.ignored == 1
    plc = load(slave(baud=19200, parity='"even"'), baud=19200, parity=2)
    assert msg(plc, 1, 0, 40001, 1)["error"] == 0 and plc["VW100"] == 42
    with pytest.raises(PlcConfigError, match="baud must be one of"):
        load_plant(slave(baud=1000))
