"""The Modbus RTU slave library (MBUS_INIT, MBUS_SLAVE) answering the
plant's scripted Modbus master, and a linked CPU's MBUS_MSG, over the
port's exact-timed serial model (plcrt.devices.modbus.slavelib,
plcrt.devices.modbus.plantmaster; docs/modbus.md "Modbus slave library").

Times: k characters of b bits at B baud sent from t end at
t + ceil(k * b * 10^6 / B) µs; a frame is known ended 3.5 characters
(ceil(7 * b * 10^6 / 2B) µs at 19200 baud and below) plus Delay ms after
its last stop bit; the slave answers at the MBUS_SLAVE call of the first
scan after that (1 ms scans here: the next whole ms).
"""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt
from plcrt.devices.modbus.master import master_of
from plcrt.devices.modbus.rtu import frame
from plcrt.devices.modbus.slavelib import slave_of
from plcrt.devices.plant import load_plant
from plcrt.errors import PlcConfigError

#: OB1: MBUS_INIT while M0.0 with every input in V memory (Mode VB200, Addr
#: VB201, Baud VD202, Parity VB206, Delay VW208, MaxIQ VW210, MaxAI VW212,
#: MaxHold VW214, HoldStart VD216); MBUS_SLAVE every scan; VW300 counts Done
PROGRAM = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     M0.0
CALL   MBUS_INIT, VB200, VB201, VD202, VB206, VW208, VW210, VW212, VW214, VD216, M0.1, MB1
Network 2
LD     SM0.0
CALL   MBUS_SLAVE, M0.2, MB2
Network 3
LD     M0.2
INCW   VW300
END_ORGANIZATION_BLOCK
"""
V = 0x08000000   #: pointer to VB0 (&VB0)
HOLD = 1000      #: HoldStart VB1000 in the tests


def master(*requests: dict, **keys) -> str:
    """A plant file: the scripted master at port 0 with *requests*."""
    lines = ["[port.0.modbus_master]"] + [f"{k} = {_toml(v)}" for k, v in keys.items()]
    for r in requests:
        lines.append("[[port.0.modbus_master.request]]")
        head = {"at_ms": 10} if "raw" in r else {"at_ms": 10, "slave": 1}
        lines += [f"{k} = {_toml(v)}" for k, v in {**head, **r}.items()]
    return "\n".join(lines) + "\n"


def _toml(v) -> str:
    return f'"{v}"' if isinstance(v, str) else str(v).lower() if isinstance(v, bool) else str(v)


def load(plant: str = "", mode: int = 1, addr: int = 1, baud: int = 9600, parity: int = 0,
         delay: int = 0, max_iq: int = 128, max_ai: int = 32, max_hold: int = 100,
         hold: int = V + HOLD, program: str = PROGRAM, **kw) -> plcrt.Plc:
    """The slave program with MBUS_INIT run once (the first scan, 0..1 ms)."""
    plc = plcrt.load(program, plant=load_plant(plant) if plant else None, scan_ms=1, **kw)
    plc["VB200"], plc["VB201"], plc["VD202"], plc["VB206"] = mode, addr, baud, parity
    plc["VW208"], plc["VW210"], plc["VW212"], plc["VW214"] = delay, max_iq, max_ai, max_hold
    plc["VD216"] = hold
    plc["M0.0"] = 1
    plc.scan()
    plc["M0.0"] = 0
    return plc


def answers(plc: plcrt.Plc) -> list[dict]:
    return plc.ports[0].peer.responses


# ---------------------------------------------------------------- reads
def test_read_holding_registers_exact_times_9600():
    """Read 40001..40002 (V words at HoldStart): the master's 8-byte request
    from 10 000 µs ends 8334 µs later; the slave knows it ended 3646 µs
    after (11 980 + 10 000), the MBUS_SLAVE of the scan at 22 000 µs answers
    9 bytes (9375 µs), and the master has them 3646 µs after the last."""
    plc = load(master({"function": 3, "address": 0, "count": 2}))
    plc["VW1000"], plc["VW1002"] = 42, 7
    plc.run(0.05)
    [r] = answers(plc)
    assert r["values"] == [42, 7] and r["error"] is None and r["exception"] is None
    assert (r["sent"], r["sent_end"]) == (10_000, 18_334)
    rec = slave_of(plc).log[0]
    assert (rec["known"], rec["served"], rec["error"]) == (21_980, 22_000, 0)
    assert r["first_char"] == 22_000 + 1042 and r["last_char"] == 22_000 + 9375
    assert r["finished"] == 22_000 + 9375 + 3646
    assert r["response"] == frame(bytes.fromhex("010304002A0007"))
    assert plc["VW300"] == 1 and plc["MB2"] == 0


def test_read_times_at_19200_even_parity():
    """At 19200 baud, even parity (11 bits a character): the request ends
    4584 µs after 10 000, the gap is 2006 µs, the answer (11 bytes for 3
    registers) takes 6303 µs from the scan at 17 000 µs."""
    plc = load(master({"function": 3, "address": 1, "count": 3}, parity="even"),
               baud=19200, parity=2)
    plc["VW1002"], plc["VW1004"], plc["VW1006"] = 7, 9, 1000
    plc.run(0.05)
    [r] = answers(plc)
    assert r["values"] == [7, 9, 1000]
    assert plc["SMB30"] == 0x45
    assert r["sent_end"] == 14_584 and slave_of(plc).log[0]["known"] == 14_584 + 2006
    assert r["first_char"] == 17_000 + 573 and r["last_char"] == 17_000 + 6303
    assert r["finished"] == 17_000 + 6303 + 2006


def test_delay_extends_the_end_of_message_timeout():
    """Delay 5 ms: the request is known ended 5 ms later (26 980 µs), so the
    answer starts at the scan from 27 000 µs."""
    plc = load(master({"function": 3, "address": 0, "count": 1}), delay=5)
    plc.run(0.05)
    assert slave_of(plc).log[0]["known"] == 26_980
    assert answers(plc)[0]["first_char"] == 27_000 + 1042


def test_read_coils_inputs_and_input_registers():
    """00001.. are Q0.0.. (function 1), 10001.. I0.0.. (2), 30001.. AIW0.. (4)."""
    plc = load(master({"function": 1, "address": 0, "count": 10},
                      {"function": 2, "address": 3, "count": 3},
                      {"function": 4, "address": 1, "count": 2}))
    plc["QB0"], plc["QB1"] = 0x0D, 0x03
    plc["I0.4"] = 1
    plc["AIW2"], plc["AIW4"] = 1234, 32000
    plc.run(0.15)
    coils, inputs, regs = answers(plc)
    assert coils["values"] == [1, 0, 1, 1, 0, 0, 0, 0, 1, 1]
    assert inputs["values"] == [0, 1, 0]
    assert regs["values"] == [1234, 32000]
    assert plc["VW300"] == 3


# ---------------------------------------------------------------- writes
def test_writes_of_coils_and_holding_registers():
    """Function 5 sets Q0.3, 15 writes Q1.0..Q2.0, 6 writes VW1008 (40005),
    16 writes VW1000, VW1002; each is answered with the echo."""
    plc = load(master({"function": 5, "address": 3, "values": [1]},
                      {"function": 15, "address": 8, "values": [1, 0, 1, 1, 0, 0, 0, 0, 1]},
                      {"function": 6, "address": 4, "values": [4321]},
                      {"function": 16, "address": 0, "values": [11, 12]}))
    plc.run(0.2)
    assert [r["error"] for r in answers(plc)] == [None] * 4
    assert [r["exception"] for r in answers(plc)] == [None] * 4
    assert plc["Q0.3"] == 1 and plc["QB1"] == 0x0D and plc["Q2.0"] == 1
    assert (plc["VW1008"], plc["VW1000"], plc["VW1002"]) == (4321, 11, 12)
    assert answers(plc)[2]["response"] == frame(bytes.fromhex("0106000410E1"))
    assert plc["VW300"] == 4 and plc["MB2"] == 0


def test_broadcast_write_is_run_and_never_answered():
    """Slave 0: the register is written, MBUS_SLAVE reports Done with Error
    0, the CPU sends nothing; the master's request has ended after its gap."""
    plc = load(master({"slave": 0, "function": 6, "address": 2, "values": [77]}))
    plc.run(0.05)
    [r] = answers(plc)
    assert plc["VW1004"] == 77 and plc["VW300"] == 1 and plc["MB2"] == 0
    assert plc.ports[0].sent == 0 and r["response"] == b""
    assert r["finished"] == 18_334 + 3646 and not r["timeout"]


def test_another_slave_address_is_not_answered():
    """A request for slave 2 is dropped: no Done, nothing sent, the master
    times out after its timeout_ms."""
    plc = load(master({"slave": 2, "function": 3, "address": 0, "count": 1}, timeout_ms=30))
    plc.run(0.1)
    [r] = answers(plc)
    assert r["timeout"] and r["finished"] == 18_334 + 30_000
    assert plc["VW300"] == 0 and plc.ports[0].sent == 0


# ---------------------------------------------------------------- exceptions
@pytest.mark.parametrize("req, exception, error", [
    ({"function": 7, "address": 0, "count": 1}, 1, 8),       # no such function
    ({"function": 3, "address": 99, "count": 2}, 2, 9),      # past MaxHold 100
    ({"function": 3, "address": 0, "count": 101}, 2, 9),
    ({"function": 16, "address": 99, "values": [1, 2]}, 2, 9),
    ({"function": 1, "address": 127, "count": 2}, 2, 9),     # past MaxIQ 128
    ({"function": 2, "address": 128, "count": 1}, 2, 9),
    ({"function": 4, "address": 32, "count": 1}, 2, 9),      # past MaxAI 32
    ({"function": 3, "address": 0, "count": 0}, 3, 9),       # count 0: exception 3
])
def test_exceptions(req, exception, error):
    """The slave answers an exception (function + 16#80, code); MBUS_SLAVE
    reports Done with Error 8 (bad function) or 9 (bad address or value)."""
    plc = load(master(req))
    plc["VW1198"] = 5
    plc.run(0.05)
    [r] = answers(plc)
    assert r["exception"] == exception
    assert r["response"] == frame(bytes((1, req["function"] | 0x80, exception)))
    assert (plc["VW300"], plc["MB2"]) == (1, error)
    assert plc["VW1198"] == 5          # nothing written
    assert any(f"Error {error}" in d.message for d in plc.diagnostics)


def test_limits_come_from_mbus_init():
    """MaxHold 2, MaxIQ 8, MaxAI 0: 40003, 00009 and 30001 are exception 2."""
    plc = load(master({"function": 3, "address": 1, "count": 1},
                      {"function": 3, "address": 2, "count": 1},
                      {"function": 5, "address": 8, "values": [1]},
                      {"function": 4, "address": 0, "count": 1}),
               max_hold=2, max_iq=8, max_ai=0)
    plc.run(0.2)
    assert [r["exception"] for r in answers(plc)] == [None, 2, 2, 2]
    assert plc["Q1.0"] == 0


def test_a_crc_error_is_error_7_without_answer():
    """A frame with a wrong CRC: MBUS_SLAVE reports Done and Error 7; no answer."""
    plc = load(master({"raw": "01 03 00 00 00 02 00 00"}, timeout_ms=20))
    plc.run(0.05)
    assert answers(plc)[0]["timeout"] and plc.ports[0].sent == 0
    assert (plc["VW300"], plc["MB2"]) == (1, 7)


def test_master_at_another_rate_is_garbled():
    """The master at 19200 baud, the slave at 9600: its characters arrive
    with errors (SM3.0 for the library: Error 6), nothing is answered."""
    plc = load(master({"function": 3, "address": 0, "count": 1}, baud=19200, timeout_ms=20))
    plc.run(0.05)
    assert answers(plc)[0]["timeout"] and plc.ports[0].sent == 0
    assert (plc["VW300"], plc["MB2"]) == (1, 6)


# ---------------------------------------------------------------- MBUS_INIT
@pytest.mark.parametrize("params, error", [
    ({"baud": 9601}, 2), ({"parity": 3}, 2), ({"addr": 0}, 3), ({"addr": 248}, 3),
    ({"mode": 2}, 4), ({"delay": 40000}, 4), ({"max_iq": 129}, 4), ({"max_ai": 33}, 4),
    ({"hold": 0x03000000}, 1), ({"hold": V + 10200, "max_hold": 100}, 1)])
def test_init_parameter_errors(params, error):
    """Bad parameters: the manual's Error (1 memory range, 2 baud or parity,
    3 address, 4 another parameter); the port stays PPI; MBUS_SLAVE then
    reports Error 10 (slave function not enabled)."""
    plc = load(**params)
    assert (plc["M0.1"], plc["MB1"]) == (1, error)
    assert plc["SMB30"] == 0 and plc.ports[0].owner is None
    plc.scan()
    assert (plc["M0.2"], plc["MB2"]) == (1, 10)


def test_init_takes_the_port_and_mode_0_gives_it_back():
    """Mode 1: SMB30 freeport 9600 no parity, the library owns the port;
    Mode 0: PPI again, and requests are no longer answered."""
    plc = load(master({"function": 3, "address": 0, "count": 1, "period_ms": 30, "repeat": 3},
                      timeout_ms=10))
    assert plc["SMB30"] == 0x09 and plc.ports[0].owner is slave_of(plc)
    assert (plc["M0.1"], plc["MB1"]) == (1, 0)
    plc.run(0.03)
    plc["VB200"], plc["M0.0"] = 0, 1
    plc.scan()
    assert plc["SMB30"] == 0 and plc.ports[0].owner is None
    plc["M0.0"] = 0
    plc.run(0.1)
    assert [r["timeout"] for r in answers(plc)] == [False, True, True]
    assert [r["sent"] for r in answers(plc)] == [10_000, 40_000, 70_000]


INT_PROGRAM = PROGRAM.replace("END_ORGANIZATION_BLOCK", """Network 4
LD     SM0.1
ATCH   CHAR, 8
ENI
END_ORGANIZATION_BLOCK
INTERRUPT_BLOCK CHAR:INT0
BEGIN
Network 1
LD     SM0.0
INCW   VW310
END_INTERRUPT_BLOCK""")


def test_the_program_sees_none_of_the_librarys_characters():
    """While the library owns the port, the receive-character event 8 does
    not reach the program's routine."""
    plc = load(master({"function": 3, "address": 0, "count": 1}), program=INT_PROGRAM)
    plc.run(0.05)
    assert answers(plc)[0]["values"] == [0] and plc["VW310"] == 0


SMART = PROGRAM.replace("VB206, VW208", "VB206, VB207, VW208")


@pytest.mark.parametrize("cpu, port, error", [("CPU226", 1, 0), ("CPU226", 2, 11),
                                              ("CPU224", 1, 12)])
def test_smart_init_port_input(cpu, port, error):
    """The SMART MBUS_INIT (a Port input): port 1 is SMB130 and answers there;
    Port 2 is Error 11; port 1 of a one-port CPU Error 12."""
    plant = master({"function": 3, "address": 0, "count": 1}).replace("port.0", f"port.{port}")
    plc = plcrt.load(SMART, plant=load_plant(plant) if error == 0 else None, scan_ms=1,
                     cpu=cpu)
    plc["VB200"], plc["VB201"], plc["VD202"], plc["VB207"] = 1, 1, 9600, port
    plc["VW210"], plc["VW214"], plc["VD216"], plc["M0.0"] = 128, 10, V + HOLD, 1
    plc["VW1000"] = 99
    plc.scan()
    assert plc["MB1"] == error
    if not error:
        assert plc["SMB130"] == 0x09 and plc.ports[1].owner is slave_of(plc)
        plc.run(0.05)
        assert plc.ports[1].peer.responses[0]["values"] == [99]


# ---------------------------------------------------------------- the export
def sbr(name: str, number: int, params: list[tuple[str, str]]) -> str:
    out = [f"SUBROUTINE_BLOCK {name}:SBR{number}", "TITLE=library block"]
    for section in ("IN", "OUT"):
        decls = [(i, t) for i, (s, t) in enumerate(params) if s == section]
        if decls:
            out.append(f"VAR_{'INPUT' if section == 'IN' else 'OUTPUT'}")
            out += [f"p{i}:{t};" for i, t in decls]
            out.append("END_VAR")
    out += ["BEGIN", "END_SUBROUTINE_BLOCK"]
    return "\n".join(out) + "\n"


INIT_ITF = [("IN", "BYTE"), ("IN", "BYTE"), ("IN", "DWORD"), ("IN", "BYTE"), ("IN", "WORD"),
            ("IN", "WORD"), ("IN", "WORD"), ("IN", "WORD"), ("IN", "DWORD"), ("OUT", "BOOL"),
            ("OUT", "BYTE")]
SLAVE_ITF = [("OUT", "BOOL"), ("OUT", "BYTE")]
EXPORT = PROGRAM.replace("CALL   MBUS_INIT", "CALL   SBR1").replace("CALL   MBUS_SLAVE",
                                                                     "CALL   SBR2")


def test_export_protected_blocks_run_the_library():
    """An export's empty MBUS_INIT / MBUS_SLAVE with the library's interface
    run the library, with one load warning naming plcrt's choices."""
    text = EXPORT + sbr("MBUS_INIT", 1, INIT_ITF) + sbr("MBUS_SLAVE", 2, SLAVE_ITF)
    plc = load(master({"function": 3, "address": 0, "count": 1}), program=text)
    plc["VW1000"] = 5
    plc.run(0.05)
    assert answers(plc)[0]["values"] == [5]
    warns = [d.message for d in plc.diagnostics]
    assert sum("Modbus RTU slave library" in w and "Error 4, 6, 7, 9, 10" in w
               for w in warns) == 1
    assert not any("no code" in w or "own subroutine" in w for w in warns)


def test_export_block_with_another_interface_runs_its_own_code():
    """An empty MBUS_INIT whose Delay is an INT is not the library's: the
    program's own (empty) subroutine runs, with a warning; the port stays PPI."""
    itf = INIT_ITF[:4] + [("IN", "INT")] + INIT_ITF[5:]
    text = EXPORT + sbr("MBUS_INIT", 1, itf) + sbr("MBUS_SLAVE", 2, SLAVE_ITF)
    plc = load(program=text)
    own = [d.message for d in plc.diagnostics if "own subroutine runs" in d.message]
    assert len(own) == 1 and "MBUS_INIT" in own[0]
    assert plc["SMB30"] == 0 and plc["M0.1"] == 0


# ---------------------------------------------------------------- two CPUs
def test_two_linked_cpus_master_and_slave():
    """programs/modbus/poll.awl (MBUS_CTRL/MBUS_MSG, 10 ms scans) on CPU A
    linked to programs/modbus/slave.awl (MBUS_INIT/MBUS_SLAVE, 7 ms scans)
    on CPU B: A reads B's 40001..40004 (VW1000..) and writes VW100 + 1 to
    B's 40005 (VW1008).  The first read: sent at 0, known ended by B at
    11 980 µs, served by B's scan at 14 000 µs, 13 bytes to 27 542 µs."""
    root = Path(__file__).resolve().parents[2] / "programs" / "modbus"
    a = plcrt.load(root / "poll.awl", scan_ms=10)
    b = plcrt.load(root / "slave.awl", scan_ms=7)
    net = plcrt.link(a, 0, b, 0)
    b["VW1002"], b["VW1004"] = 35, 7
    net.run(1.0)
    first = slave_of(b).log[0]
    assert (first["known"], first["served"], first["answer_end"]) == (11_980, 14_000, 27_542)
    assert master_of(a).log[0]["first_char"] == 15_042
    assert (a["MB3"], a["MB4"], b["MB2"]) == (0, 0, 0)
    assert (a["VW20"], b["VW20"]) == (14, 28)          # 14 reads and 14 writes served
    assert (a["VW100"], a["VW102"], a["VW104"]) == (b["VW1000"], 35, 7) == (1, 35, 7)
    assert b["VW1008"] == 2 and b["QB1"] == 2


# ---------------------------------------------------------------- the sample
def test_sample_slave_with_the_plant_master():
    """programs/modbus/slave.awl against master_plant.toml for 1 s: 10 reads,
    one register and 8 coils written, 4 reads of the inputs; 40005 drives QB1."""
    root = Path(__file__).resolve().parents[2] / "programs" / "modbus"
    plc = plcrt.load(root / "slave.awl", plant=root / "master_plant.toml", scan_ms=10)
    plc["I0.2"] = 1
    plc.run(1.0)
    rs = plc.ports[0].peer.responses
    assert len(rs) == 16 and all(r["error"] is None and r["exception"] is None for r in rs)
    assert plc["VW20"] == 16 and plc["QB1"] == 0xA5 and plc["QB0"] == 0x85
    assert [r["values"] for r in rs if r["function"] == 2][0] == [0, 0, 1, 0, 0, 0, 0, 0]


# ---------------------------------------------------------------- plant keys
@pytest.mark.parametrize("text, words", [
    ("[port.0.modbus_master]\ntimeout_ms = 5\n", "request is missing"),
    (master({"function": 3, "address": 0}), "count is missing"),
    (master({"function": 3, "address": 0, "count": 1, "valeus": [1]}), "unknown key"),
    (master({"function": 16, "address": 0, "values": [70000]}), "0..65535"),
    (master({"function": 5, "address": 0, "values": [1, 1]}), "1..1 value"),
    (master({"slave": 0, "function": 3, "address": 0, "count": 1}), "broadcast"),
    (master({"slave": 248, "function": 3, "address": 0, "count": 1}), "0..247"),
    (master({"raw": "01 03", "function": 3}), "cannot go with it"),
    (master({"function": 3, "address": 0, "count": 1}, parity="mark"), "parity"),
    (master({"function": 3, "address": 0, "count": 1})
     + "[port.0.modbus_slave]\naddress = 1\n", "one device per port")])
def test_plant_keys_are_checked(text, words):
    with pytest.raises(PlcConfigError, match=words):
        load_plant(text)


def test_periodic_requests_and_a_fork():
    """period_ms / repeat: the request goes at 10, 40 and 70 ms; a fork in
    the middle of the first answer runs on with its own slave library and
    master.  A request due while the last one waits goes when it has ended."""
    plc = load(master({"function": 3, "address": 0, "count": 1, "period_ms": 30, "repeat": 3}))
    plc.run(0.025)
    twin = plc.fork()
    twin["VW1000"] = 8
    twin.run(0.08)
    plc.run(0.08)
    assert [r["sent"] for r in answers(twin)] == [10_000, 40_000, 70_000]
    assert [r["values"] for r in answers(twin)] == [[0], [8], [8]]
    assert [r["values"] for r in answers(plc)] == [[0], [0], [0]]
    assert slave_of(twin) is not slave_of(plc) and len(slave_of(twin).log) == 3
    busy = load(master({"function": 3, "address": 0, "count": 1, "period_ms": 20, "repeat": 2}))
    busy.run(0.1)
    # the second is due at 30 000 µs while the first's answer ends at 29 292 + 3646
    assert [r["sent"] for r in answers(busy)] == [10_000, 32_938]


def test_a_request_waits_while_the_last_answer_is_sent():
    """Half duplex: a second request (from a scripted device, unasked for)
    known ended at 41 980 µs while the 205-byte answer to the first runs
    until 235 542 µs is served by the first scan after that answer."""
    first = frame(bytes.fromhex("010300000064")).hex(" ")
    second = frame(bytes.fromhex("010300000001")).hex(" ")
    plant = (f'[[port.0.send]]\nat = 0.01\ndata = "{first}"\n'
             f'[[port.0.send]]\nat = 0.03\ndata = "{second}"\n')
    plc = load(plant)
    plc.run(0.3)
    one, two = slave_of(plc).log
    assert (one["served"], one["answer_end"]) == (22_000, 22_000 + 213_542)
    assert two["known"] == 41_980 and two["served"] == 236_000
    assert plc["VW300"] == 2
