"""What is at the other end of a port: a scripted device from the plant
(plcrt.devices.portdev), another plcrt CPU linked port to port
(plcrt.engine.link), and the jobs between linked CPUs: NETR/NETW (PPI
master) and GET/PUT (Ethernet; plcrt.engine.netjobs).  Times are analytic
(see tests/isa/test_ports.py)."""

from __future__ import annotations

import pytest

import plcrt
from plcrt.engine.netjobs import NO_ANSWER_US
from plcrt.errors import PlcConfigError

from test_ports import end, program, record, received

DEVICE = """
[port.0]
[[port.0.reply]]
request = "01 03"
reply = "AA BB CC"
delay_ms = 5
[[port.0.reply]]
request = "02"
reply = "DD"
"""

#: XMT the VB100 table once; when it is out (event 9, the port is half
#: duplex) RCV into VB200 any character, with a 20 ms message timer
ASK = ("LD SM0.1\nMOVB 16#09, SMB30\nMOVB 16#9C, SMB87\nMOVW +0, SMW90\nMOVW +20, SMW92\n"
       "MOVB 10, SMB94\nATCH INT_0, 23\nATCH INT_1, 9\nENI\nXMT VB100, 0")
DONE = "LD SM0.0\nINCW VW0\nMOVB SMB86, VB10"
LISTEN = "LD SM0.0\nRCV VB200, 0"


def ask(data: str, plant: str = DEVICE) -> plcrt.Plc:
    plc = plcrt.load(program(ASK, DONE, LISTEN), plant=plant, scan_ms=1)
    raw = bytes.fromhex(data)
    plc["VB100"] = len(raw)
    for k, b in enumerate(raw):
        plc[f"VB{101 + k}"] = b
    return plc


def test_the_scripted_device_answers_a_request_after_its_delay():
    """'01 03' ends at 2084 µs, when the RCV starts; the reply starts 5 ms
    later; its three characters end at 7084 + 3125 µs; the 20 ms message
    timer (from the RCV) ends the receive with the reply in the buffer."""
    plc = ask("01 03")
    runs = record(plc)
    plc.run(0.04)
    assert received(plc) == bytes.fromhex("AA BB CC")
    assert runs == [(1, 2084), (0, 22_084)] and plc["VB10"] == 0x04
    assert plc.ports[0].peer.answered == 1 and plc.ports[0].unanswered == []
    assert plc.ports[0].items == []
    t_reply = end(0, 2, 10, 9600) + 5000
    assert plc.ports[0].received == 3
    assert end(t_reply, 3, 10, 9600) == 10209


def test_two_requests_in_one_transmission_are_answered_in_turn():
    """'02 01 03': 02 is answered at once: 'DD' arrives while the port
    still sends 01 03, before its RCV (half duplex), so it is a character
    (SMB2) but not in the message; 01 03 is answered 5 ms later."""
    plc = ask("02 01 03")
    plc.run(0.04)
    assert received(plc) == bytes.fromhex("AA BB CC")
    assert plc.ports[0].received == 4 and plc.ports[0].peer.answered == 2


def test_bytes_nobody_answers_are_in_the_diagnostics():
    plc = ask("01 04 7F")
    plc.run(0.03)
    assert plc.ports[0].unanswered == [(end(0, 3, 10, 9600), bytes.fromhex("01 04 7F"))]
    msg = [d.message for d in plc.diagnostics if "unanswered" in d.message]
    assert msg and "01 04 7F" in msg[0] and "no reply" in msg[0]
    assert plc["VB200"] == 0 and plc["VB10"] == 0x04      # the time-out ends the receive


def test_a_port_without_a_device_reports_what_it_sent():
    plc = ask("41 42", plant="[port.0]\naddress = 2\n")
    plc.run(0.03)
    assert any("41 42" in d.message and "no device is at the port" in d.message
               for d in plc.diagnostics)


def test_many_unanswered_transmissions_are_summarised():
    src = program("LD SM0.1\nMOVB 16#09, SMB30\nMOVB 1, VB100\n\nLD SM0.0\nXMT VB100, 0")
    plc = plcrt.load(src, scan_ms=5)
    plc.run(1.0)                      # one character every 5 ms: 200 transmissions
    assert plc.ports[0].unanswered_count == 200
    assert sum("went unanswered" in d.message for d in plc.diagnostics) == 20
    assert any("more unanswered transmissions follow" in d.message for d in plc.diagnostics)


@pytest.mark.parametrize("plant, match", [
    ("[port.2]\n", "ports 0 and 1"),
    ("[port.0]\nspeed = 1\n", "unknown key"),
    ("[port.0]\nppi_baud = 9601\n", "ppi_baud must be one of"),
    ("[port.0]\naddress = 127\n", "address must be a whole number in 0..126"),
    ("[[port.0.reply]]\nrequest = \"01 0\"\nreply = \"02\"\n", "hex bytes"),
    ("[[port.0.reply]]\nrequest = \"01\"\n", "reply is missing"),
    ("[[port.0.reply]]\nrequest = \"01\"\nreply = \"02\"\nbad_parity = [1]\n",
     "byte positions 0..0"),
    ("[[port.0.reply]]\nrequest = \"01\"\nreply = \"02\"\n[[port.0.reply]]\n"
     "request = \"01\"\nreply = \"03\"\n", "already answered"),
    ("[[port.0.send]]\nat = -1\ndata = \"01\"\n", "at must be a number"),
    ("[ethernet]\nip = \"300.1.1.1\"\n", "IPv4 address"),
    ("[ethernet]\nip = \"192.168.2.255\"\n", "not an address a CPU can have"),
    ("[ethernet]\n", "ip is missing"),
    ("[ethernet]\nip = \"10.0.0.1\"\nlatency_ms = 0.001\n", "at least 0.002"),
])
def test_plant_port_keys_are_validated_with_their_location(plant, match):
    with pytest.raises(PlcConfigError, match=match) as e:
        plcrt.load(program("LD SM0.0\n= Q0.0"), plant=plant)
    assert "<plant>" in str(e.value)


def test_port_1_in_the_plant_of_a_one_port_cpu_is_refused():
    with pytest.raises(PlcConfigError, match="port 0 only"):
        plcrt.load(program("LD SM0.0\n= Q0.0"), plant="[port.1]\n", cpu="CPU224")


def test_a_fork_with_a_receive_in_progress_runs_the_same():
    plc = ask("01 03")
    plc.run(0.004)                      # the request is out, the reply not yet
    twin = plc.fork()
    plc.run(0.03)
    twin.run(0.03)
    assert received(twin) == received(plc) == bytes.fromhex("AA BB CC")
    assert twin["VW0"] == plc["VW0"] == 1


# ---------------------------------------------------------------- two CPUs
#: A sends 4 bytes, then (event 9) receives 4, with a 50 ms message timer
MASTER = ("LD SM0.1\nMOVB 16#09, SMB30\nMOVB 16#9C, SMB87\nMOVW +0, SMW90\nMOVW +50, SMW92\n"
          "MOVB 4, SMB94\nATCH INT_0, 23\nATCH INT_1, 9\nENI\nMOVB 4, VB100\n"
          "MOVD 16#01020304, VD101\nXMT VB100, 0")
#: B echoes each message with every byte + 1 from its message routine and
#: receives again when the echo is out
SLAVE = ("LD SM0.1\nMOVB 16#09, SMB30\nMOVB 16#90, SMB87\nMOVW +0, SMW90\nMOVB 4, SMB94\n"
         "ATCH INT_0, 23\nATCH INT_1, 9\nENI\nRCV VB200, 0")
ECHO = ("LD SM0.0\nINCW VW0\nMOVB SMB86, VB10\nMOVD VD201, VD220\nMOVD VD201, VD101\n"
        "+D 16#01010101, VD101\nMOVB 4, VB100\nXMT VB100, 0")


def test_two_linked_cpus_exchange_xmt_and_rcv_at_the_exact_times():
    """A sends 4 bytes at 0 and starts receiving when they are out (4167 µs);
    B's receive ends by count when the 4th stop bit ends (4167 µs) and its
    routine sends the answer then; A has it when that answer's 4th stop bit
    ends (8334 µs).  Both CPUs see the same times although their scans
    differ (10 ms and 3 ms)."""
    a = plcrt.load(program(MASTER, DONE, LISTEN), scan_ms=10)
    b = plcrt.load(program(SLAVE, ECHO, LISTEN), scan_ms=3)
    runs_a, runs_b = record(a), record(b)
    net = plcrt.link(a, 0, b, 0)
    net.run(0.03)
    t1 = end(0, 4, 10, 9600)
    assert runs_b == [(0, t1), (1, end(t1, 4, 10, 9600))] and b["VB10"] == 0x02
    assert b["VD220"] == 0x01020304 and b["VB200"] == 0     # copied; receiving again
    assert runs_a == [(1, t1), (0, end(t1, 4, 10, 9600))] and a["VB10"] == 0x02
    assert received(a) == bytes.fromhex("02 03 04 05")
    assert a.time == pytest.approx(0.03) and b.time == pytest.approx(0.030)


def test_linked_cpus_with_other_baud_rates_receive_errors():
    a = plcrt.load(program(MASTER, DONE, LISTEN), scan_ms=10)
    b = plcrt.load(program(SLAVE.replace("16#09", "16#05"), ECHO, LISTEN), scan_ms=3)
    plcrt.link(a, 0, b, 0).run(0.02)
    assert b["VB10"] == 0x01             # the first character ends the receive: parity
    assert any("the port is set to 19200 baud" in d.message for d in b.diagnostics)


def test_a_linked_plc_is_run_by_its_network_only():
    a, b = plcrt.load(program(SLAVE, DONE, LISTEN)), plcrt.load(program(SLAVE, DONE, LISTEN))
    plcrt.link(a, 0, b, 0)
    with pytest.raises(PlcConfigError, match="run them together"):
        a.scan()
    with pytest.raises(PlcConfigError, match="already has something"):
        plcrt.link(a, 0, b, 0)


def test_link_arguments_are_checked():
    a = plcrt.load(program(SLAVE, DONE, LISTEN))
    b = plcrt.load(program(SLAVE, DONE, LISTEN), cpu="CPU224")
    with pytest.raises(PlcConfigError, match="port"):
        plcrt.link(a, 0, b, 1)
    with pytest.raises(PlcConfigError, match="loaded PLCs"):
        plcrt.link(a, 0, "b", 0)
    b.scan()
    with pytest.raises(PlcConfigError, match="at the others' time"):
        plcrt.link(a, 0, b, 0)


# ---------------------------------------------------------------- NETR / NETW
#: A is PPI master on port 0 (SMB30 = 16#0A: 9600 baud, protocol 10); its
#: NETW table at VB300 writes 4 bytes to station 3's VB500, its NETR table at
#: VB340 reads 2 bytes of station 3's VW600.
NET = ("LD SM0.1\nMOVB 16#0A, SMB30\nMOVB 3, VB301\nMOVD &VB500, VD302\nMOVB 4, VB306\n"
       "MOVD 16#CAFEBABE, VD307\nMOVB 3, VB341\nMOVD &VB600, VD342\nMOVB 2, VB346\n"
       "NETW VB300, 0\nNETR VB340, 0")
STATION_3 = "[port.0]\naddress = 3\n"


def netw_netr(station: str = STATION_3, remote_smb30: str = "16#08"):
    a = plcrt.load(program(NET), scan_ms=5)
    b = plcrt.load(program(f"LD SM0.1\nMOVB {remote_smb30}, SMB30\nMOVW 16#1234, VW600"),
                   plant=station, scan_ms=5)
    return a, b, plcrt.link(a, 0, b, 0)


def ppi_end(chars: int) -> int:
    return end(0, chars, 11, 9600)


def test_netw_and_netr_between_linked_cpus():
    """NETW of 4 bytes: 37 + 4 request characters and 1 + 6 + 24 for the
    rest, 11-bit characters at 9600 baud: done at 82.5 ms; NETR of 2 bytes:
    33 + 1 + 6 + 27 + 2 = 69 characters: done at 79.06 ms.  A (active) is
    set until then; D then, and the data have moved."""
    a, b, net = netw_netr()
    net.run(0.005)
    assert a["VB300"] == 0x40 and a["VB340"] == 0x40
    net.run(0.070)                       # 75 ms
    assert a["VB340"] == 0x40 and b["VD500"] & 0xFFFFFFFF == 0xCAFEBABE   # written at the request
    net.run(ppi_end(69) / 1e6 - 0.075)
    assert a["VB340"] == 0x80 and a["VW347"] == 0x1234 and a["VB300"] == 0x40
    net.run(ppi_end(72) / 1e6 - a.time + 0.000001)
    assert a["VB300"] == 0x80


def test_netw_to_a_station_nobody_has_times_out_with_error_1():
    a, b, net = netw_netr(station="[port.0]\naddress = 9\n")
    net.run(0.2)
    assert a["VB300"] == 0xA1 and a["VB340"] == 0xA1 and b["VD500"] == 0
    t = ppi_end(41) + NO_ANSWER_US
    assert t < 200_000


def test_a_remote_port_in_freeport_mode_does_not_answer_ppi():
    a, b, net = netw_netr(remote_smb30="16#09")
    net.run(0.3)
    assert a["VB300"] == 0xA1 and b["VD500"] == 0


def test_netr_without_ppi_master_mode_is_error_5():
    a = plcrt.load(program(NET.replace("16#0A", "16#08")))
    a.scan()
    assert a["VB300"] == 0xA5 and a["VB340"] == 0xA5
    assert any("not PPI master" in d.message for d in a.diagnostics)


@pytest.mark.parametrize("length, error", [(0, 6), (17, 6)])
def test_an_illegal_length_is_error_6(length, error):
    a = plcrt.load(program(NET.replace("MOVB 4, VB306", f"MOVB {length}, VB306")))
    a.scan()
    assert a["VB300"] == 0xA0 | error


def test_more_than_8_jobs_is_error_4():
    tables = "\n".join(f"MOVB 3, VB{400 + 30 * k + 1}\nMOVB 1, VB{400 + 30 * k + 6}\n"
                       f"NETR VB{400 + 30 * k}, 0" for k in range(9))
    a = plcrt.load(program("LD SM0.1\nMOVB 16#0A, SMB30\n" + tables))
    a.scan()
    assert [a[f"VB{400 + 30 * k}"] for k in range(9)] == [0x40] * 8 + [0xA4]


def test_a_remote_address_outside_the_remote_memory_is_error_9():
    a = plcrt.load(program(NET.replace("MOVD &VB500", "MOVD 16#080027FE")), scan_ms=5)
    b = plcrt.load(program("LD SM0.0\n= Q0.0"), plant=STATION_3, scan_ms=5)
    plcrt.link(a, 0, b, 0).run(0.1)              # VB10238..10241: past a CPU 226's V
    assert a["VB300"] == 0xA9


# ---------------------------------------------------------------- GET / PUT
#: PUT 4 bytes of VD20 to 192.168.2.20's VB700; GET 2 bytes of its VW710
#: into VW30 (SMART tables: status, IP, 2 reserved, remote pointer, length,
#: local pointer)
GETPUT = ("LD SM0.1\nMOVD 16#C0A80214, VD401\nMOVD &VB700, VD407\nMOVB 4, VB411\n"
          "MOVD &VB20, VD412\nMOVD 16#11223344, VD20\n"
          "MOVD 16#C0A80214, VD451\nMOVD &VB710, VD457\nMOVB 2, VB461\nMOVD &VB30, VD462\n"
          "PUT VB400\nGET VB450")


def ethernet(ip: str, latency: str = "") -> str:
    return f'[ethernet]\nip = "{ip}"\n{latency}'


def test_put_and_get_between_cpus_of_a_network():
    """One way takes the plant's latency (2 ms here): the remote memory is
    read and written at 2 ms, the tables are done at 4 ms."""
    a = plcrt.load(program(GETPUT), plant=ethernet("192.168.2.10", "latency_ms = 2"),
                   scan_ms=1)
    b = plcrt.load(program("LD SM0.1\nMOVW 16#5566, VW710"), plant=ethernet("192.168.2.20"),
                   scan_ms=1)
    net = plcrt.Network(a, b)
    net.run(0.0035)
    assert a["VB400"] == 0x40 and a["VB450"] == 0x40 and b["VD700"] == 0x11223344
    net.run(0.001)
    assert a["VB400"] == 0x80 and a["VB450"] == 0x80 and a["VW30"] == 0x5566


def test_get_from_an_address_nobody_has_is_error_5():
    a = plcrt.load(program(GETPUT), plant=ethernet("192.168.2.10"), scan_ms=1)
    a.run(0.01)
    assert a["VB400"] == 0xA5 and a["VB450"] == 0xA5


@pytest.mark.parametrize("patch, error", [
    ("MOVB 0, VB411", 1), ("MOVB 213, VB411", 1), ("MOVB 1, VB405", 1),
    ("MOVD 16#C0A802FF, VD401", 1), ("MOVD 16#C0A8020A, VD401", 1),
    ("MOVD 16#0D000000, VD407", 1),
])
def test_an_illegal_put_table_is_error_1(patch, error):
    src = program(GETPUT.replace("PUT VB400", f"{patch}\nPUT VB400"))
    a = plcrt.load(src, plant=ethernet("192.168.2.10"), scan_ms=1)
    a.scan()
    assert a["VB400"] == 0xA0 | error


def test_get_of_a_remote_area_too_small_is_error_4():
    a = plcrt.load(program(GETPUT.replace("MOVD &VB710, VD457", "MOVD 16#08002800, VD457")),
                   plant=ethernet("192.168.2.10"), scan_ms=1)
    b = plcrt.load(program("LD SM0.0\n= Q0.0"), plant=ethernet("192.168.2.20"), scan_ms=1)
    plcrt.Network(a, b).run(0.01)
    assert a["VB450"] == 0xA4 and a["VB400"] == 0x80


# ---------------------------------------------------------------- the sample
def test_the_scale_sample_reads_a_weight_every_100_ms():
    """programs/ports/scale.awl: the request 'W' CR goes at 100 ms (timed
    interrupt), ends at 102084 µs; the scale answers 20 ms later with 8
    characters, whose ETX ends at 122084 + 8334 µs: the message routine
    runs then.  In 1 s: 9 answers (the 10th request goes at 1.0 s)."""
    from pathlib import Path
    root = Path(__file__).resolve().parents[2] / "programs" / "ports"
    plc = plcrt.load(root / "scale.awl", plant=root / "scale_plant.toml")
    runs = record(plc)
    plc.run(1.0)
    assert plc.diagnostics == []
    assert plc["VW10"] == 9 and plc["VW12"] == 0
    assert bytes(plc[f"VB{20 + k}"] for k in range(6)) == b"+012.5"
    first = [t for n, t in runs if n == 0][0]
    assert first == end(end(100_000, 2, 10, 9600) + 20_000, 8, 10, 9600) == 130_418
    assert (1, 102_084) in runs and (2, 100_000) in runs


def test_two_ports_of_one_cpu_can_be_linked():
    """Port 0 to port 1 of one CPU 226: what port 0 sends, port 1 receives
    (its message routine at the 4th stop bit's end)."""
    src = program("LD SM0.1\nMOVB 16#09, SMB30\nMOVB 16#09, SMB130\nMOVB 16#90, SMB187\n"
                  "MOVW +0, SMW190\nMOVB 4, SMB194\nATCH INT_0, 24\nENI\nRCV VB200, 1\n"
                  "MOVB 4, VB100\nMOVD 16#0A0B0C0D, VD101\nXMT VB100, 0",
                  "LD SM0.0\nINCW VW0\nMOVB SMB186, VB10")
    plc = plcrt.load(src, scan_ms=10)
    runs = record(plc)
    plcrt.link(plc, 0, plc, 1).run(0.02)
    assert runs == [(0, end(0, 4, 10, 9600))] and plc["VB10"] == 0x02
    assert received(plc) == bytes.fromhex("0A 0B 0C 0D")


def test_a_fork_of_a_linked_cpu_is_not_linked():
    a = plcrt.load(program(MASTER, DONE, LISTEN), scan_ms=10)
    b = plcrt.load(program(SLAVE, ECHO, LISTEN), scan_ms=3)
    net = plcrt.link(a, 0, b, 0)
    net.run(0.002)                      # A's 4 bytes are on their way to B
    twin = b.fork()
    assert twin.network is None and twin.ports[0].peer is None
    assert twin.ports[0].items == []    # what A sent stays with the linked B
    twin.run(0.02)                      # runs alone: nothing arrives
    assert twin["VW0"] == 0
    net.run(0.02)
    assert b["VW0"] == 1 and a["VW0"] == 1


def test_a_cpu_that_stops_stands_while_the_other_runs_on():
    """B executes STOP in its first scan: its time stands, A runs on and its
    request goes unanswered (A's message timer ends the receive)."""
    a = plcrt.load(program(MASTER, DONE, LISTEN), scan_ms=10)
    b = plcrt.load(program("LD SM0.1\nSTOP"), scan_ms=10)
    net = plcrt.link(a, 0, b, 0)
    net.run(0.1)
    assert b.mode == "STOP" and b.time == pytest.approx(0.01)
    assert a.time == pytest.approx(0.1) and a["VB10"] == 0x04      # A's timer ended it


def test_plcrt_run_lists_the_ports_as_json(capsys):
    import json
    from pathlib import Path
    from plcrt.cli import main
    root = Path(__file__).resolve().parents[2] / "programs" / "ports"
    code = main(["run", str(root / "scale.awl"), "--plant", str(root / "scale_plant.toml"),
                 "--seconds", "0.5", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    assert out["ports"] == [{"port": 0, "mode": "freeport", "baud": 9600, "sent": 10,
                             "received": 32, "unanswered": 0}]


def test_a_linked_cpu_cannot_go_back_in_time():
    a = plcrt.load(program(MASTER, DONE, LISTEN), scan_ms=10)
    b = plcrt.load(program(SLAVE, ECHO, LISTEN), scan_ms=3)
    snap = a.snapshot()
    plcrt.link(a, 0, b, 0).run(0.01)
    with pytest.raises(PlcConfigError, match="linked to others"):
        a.restore(snap)
    twin = a.fork()
    twin.restore(snap)                  # an unlinked twin may
    assert twin.now_us == 0


def test_a_short_ethernet_latency_shortens_the_lockstep_window():
    """latency_ms = 0.01 (10 µs one way): B's memory is written at 10 µs,
    A's PUT is done at 20 µs, although the windows are otherwise 78 µs."""
    a = plcrt.load(program(GETPUT), plant=ethernet("192.168.2.10", "latency_ms = 0.01"),
                   scan_ms=1)
    b = plcrt.load(program("LD SM0.0\n= Q0.0"), plant=ethernet("192.168.2.20"), scan_ms=1)
    seen = []
    for t in (9, 10, 11):                # B's memory as its own time line sees it
        b.ethernet.push(t, lambda t: seen.append((t, b["VD700"] & 0xFFFFFFFF)))
    net = plcrt.Network(b, a)            # B's windows run before A's
    net.run(0.000019)
    assert a["VB400"] == 0x40
    net.run(0.000001)
    assert a["VB400"] == 0x80
    # at 10 µs the probe scheduled first runs first, then the PUT's write
    assert seen == [(9, 0), (10, 0), (11, 0x11223344)]
