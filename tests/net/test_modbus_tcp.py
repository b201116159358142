"""Modbus TCP server (plcrt.net.modbus) driven by pymodbus's client while
a ladder program reacts: every function of the S7-200 slave library on
its address map (docs/network.md, "Modbus TCP"), the limits and the
exception codes, the program's own MBUS_INIT parameters, the write guard."""

from __future__ import annotations

import socket

import pytest

pymodbus = pytest.importorskip("pymodbus")
from pymodbus.client import ModbusTcpClient  # noqa: E402

import plcrt  # noqa: E402
from plcrt.devices.modbus.slavelib import slave_of  # noqa: E402
from plcrt.errors import PlcConfigError  # noqa: E402
from plcrt.net import ScanDoor  # noqa: E402

from .modbus_net_helpers import REACT, SLAVE, mbap, recv_frame, wait_for  # noqa: E402


@pytest.fixture
def served():
    """A CPU 226 running REACT in real time, served on a free port, and a
    connected pymodbus client."""
    plc = plcrt.load(REACT)
    with plcrt.serve(plc, modbus=0) as s:
        c = ModbusTcpClient("127.0.0.1", port=s.port("modbus"), timeout=5)
        assert c.connect()
        yield s, c
        c.close()


def read(s, address):
    return s.call(lambda p: p.read(address))


def ok(r):
    assert not r.isError(), r
    return r


def test_holding_registers_are_v_words_and_the_program_reacts(served):
    s, c = served
    ok(c.write_register(0, 41))                       # FC6: 40001 = VW0
    assert read(s, "VW0") == 41
    wait_for(lambda: ok(c.read_holding_registers(0, count=2)).registers == [41, 42],
             what="VW2 = VW0 + 1")
    ok(c.write_registers(10, [0x1234, 0xBEEF, 7]))    # FC16: 40011.. = VW20..
    assert [read(s, a) & 0xFFFF for a in ("VW20", "VW22", "VW24")] == [0x1234, 0xBEEF, 7]
    assert ok(c.read_holding_registers(10, count=3)).registers == [0x1234, 0xBEEF, 7]


def test_coils_are_q_bits_and_discrete_inputs_i_bits(served):
    s, c = served
    ok(c.write_coil(0, True))                         # FC5: 00001 = Q0.0
    bits = wait_for(lambda: (b := ok(c.read_coils(0, count=16)).bits)[8] and b,
                    what="Q1.0 follows Q0.0")
    assert bits[0] and bits[8] and not bits[1]
    s.call(lambda p: p.write("I0.0", 1))              # the program's Q0.1 follows I0.0
    s.call(lambda p: p.write("I1.3", 1))
    di = ok(c.read_discrete_inputs(0, count=16)).bits   # FC2: 10001.. = I
    assert di[0] and di[11] and sum(di[:16]) == 2
    wait_for(lambda: ok(c.read_coils(1, count=1)).bits[0], what="Q0.1 follows I0.0")
    ok(c.write_coil(0, False))
    assert read(s, "Q0.0") == 0


def test_write_multiple_coils_on_byte_boundaries(served):
    s, c = served
    pattern = [True, False, True, True, False, False, False, True]
    ok(c.write_coils(16, pattern))                    # FC15: Q2.0 .. Q2.7
    assert read(s, "QB2") == 0b10001101
    ok(c.write_coils(24, pattern * 2))                # QB3, QB4
    assert (read(s, "QB3"), read(s, "QB4")) == (0b10001101, 0b10001101)
    # the library: start on a byte boundary (else 02), a multiple of 8 (else 03)
    r = c.write_coils(17, pattern)
    assert r.isError() and r.exception_code == 2
    r = c.write_coils(16, pattern[:5])
    assert r.isError() and r.exception_code == 3
    assert read(s, "QB2") == 0b10001101               # a refused request writes nothing


def test_input_registers_are_aiw(served):
    s, c = served
    s.call(lambda p: p.write("AIW4", 12345))
    s.call(lambda p: p.write("AIW62", -2))
    r = ok(c.read_input_registers(0, count=32))       # FC4: 30001.. = AIW0..AIW62
    assert r.registers[2] == 12345 and r.registers[31] == 0xFFFE
    r = c.read_input_registers(32, count=1)           # CPU 226: AIW62 is the last
    assert r.isError() and r.exception_code == 2


@pytest.mark.parametrize("call, code", [
    (lambda c: c.read_holding_registers(0, count=121), 3),     # 120 words at most
    (lambda c: c.write_registers(0, [1] * 121), 3),
    (lambda c: c.read_holding_registers(999, count=2), 2),     # MaxHold 1000
    (lambda c: c.write_register(1000, 1), 2),
    (lambda c: c.read_coils(127, count=2), 2),                 # CPU 226: 128 Q bits
    (lambda c: c.read_discrete_inputs(128, count=1), 2),
])
def test_limits_are_the_library_exceptions(served, call, code):
    _, c = served
    r = call(c)
    assert r.isError() and r.exception_code == code


def test_the_limits_themselves_are_served(served):
    s, c = served
    assert len(ok(c.read_holding_registers(880, count=120)).registers) == 120
    ok(c.write_register(999, 77))                     # 40 1000 = VW1998
    assert read(s, "VW1998") == 77
    assert len(ok(c.read_coils(0, count=128)).bits) >= 128


def test_functions_the_library_lacks_are_exception_1_any_unit_is_answered(served):
    s, _ = served
    with socket.create_connection(("127.0.0.1", s.port("modbus")), timeout=5) as k:
        for fn in (7, 8, 17, 22, 23, 43, 0x41):
            k.sendall(mbap(bytes((fn, 0, 0, 0, 1)), tid=fn, unit=255))
            assert recv_frame(k) == bytes((fn | 0x80, 1))
        # FC5 with a value other than 0000 / FF00, FC16 whose byte count lies
        k.sendall(mbap(bytes((5, 0, 0, 0x12, 0x34)), unit=0))
        assert recv_frame(k) == bytes((0x85, 3))
        k.sendall(mbap(bytes((16, 0, 0, 0, 2, 3, 0, 1, 0, 2))))
        assert recv_frame(k) == bytes((0x90, 3))
        for count in (0, 2001):                       # quantities pymodbus never sends
            k.sendall(mbap(bytes((1, 0, 0)) + count.to_bytes(2, "big")))
            assert recv_frame(k) == bytes((0x81, 3))
        k.sendall(mbap(bytes((3, 0, 0, 0))))          # a read one byte short
        assert recv_frame(k) == bytes((0x83, 3))
        k.sendall(mbap(bytes((3, 0, 0, 0, 1)), tid=0xBEEF, unit=7))
        head = k.recv(7)
        assert head[:2] == b"\xbe\xef" and head[6] == 7    # transaction and unit echoed
        assert recv_frame_rest(k, head) == bytes((3, 2, 0, 0))


def recv_frame_rest(k, head):
    n = int.from_bytes(head[4:6], "big") - 1
    out = b""
    while len(out) < n:
        out += k.recv(n - len(out))
    return out


def test_a_program_with_mbus_init_gets_its_own_parameters():
    plc = plcrt.load(SLAVE.format(baud=9600, parity=0))
    with plcrt.serve(plc, modbus=0) as s:
        wait_for(lambda: s.call(lambda p: slave_of(p).enabled), what="MBUS_INIT")
        with ModbusTcpClient("127.0.0.1", port=s.port("modbus"), timeout=5) as c:
            ok(c.write_register(0, 500))              # HoldStart VB1000
            assert read(s, "VW1000") == 500
            wait_for(lambda: ok(c.read_holding_registers(0, count=2)).registers == [500, 501])
            assert ok(c.read_holding_registers(9, count=1))
            for r in (c.read_holding_registers(9, count=2),      # MaxHold 10
                      c.read_coils(15, count=2),                 # MaxIQ 16
                      c.read_discrete_inputs(16, count=1),
                      c.read_input_registers(2, count=1),        # MaxAI 2
                      c.write_coils(16, [True] * 8)):
                assert r.isError() and r.exception_code == 2
            assert len(ok(c.read_input_registers(0, count=2)).registers) == 2


def test_read_only_refuses_every_write_with_exception_2_and_logs(caplog):
    plc = plcrt.load(REACT)
    with plcrt.serve(plc, modbus=0, read_only=True) as s, \
            ModbusTcpClient("127.0.0.1", port=s.port("modbus"), timeout=5) as c:
        for r in (c.write_register(0, 5), c.write_registers(0, [5, 6]),
                  c.write_coil(0, True), c.write_coils(0, [True] * 8)):
            assert r.isError() and r.exception_code == 2
        assert read(s, "VW0") == 0 and read(s, "QB0") == 0
        assert ok(c.read_holding_registers(0, count=4))
        assert s.services["modbus"].stats["refused_writes"] == 4
    assert any("refused" in m for m in caplog.messages)


def test_allow_list_lets_only_its_ranges_be_written():
    plc = plcrt.load(REACT)
    with plcrt.serve(plc, modbus=0, allow_writes="VB10-VB19,Q2.0-Q2.7") as s, \
            ModbusTcpClient("127.0.0.1", port=s.port("modbus"), timeout=5) as c:
        ok(c.write_registers(5, [1, 2, 3, 4, 5]))     # VB10 .. VB19
        r = c.write_registers(5, [1] * 6)             # one word past the range
        assert r.isError() and r.exception_code == 2
        assert read(s, "VW20") == 0
        ok(c.write_coils(16, [True] * 8))
        r = c.write_coil(0, True)
        assert r.isError() and r.exception_code == 2


def test_a_full_door_is_exception_6_server_busy():
    plc = plcrt.load(REACT)
    with plcrt.serve(plc, modbus=0, door=ScanDoor(limit=0)) as s, \
            ModbusTcpClient("127.0.0.1", port=s.port("modbus"), timeout=5) as c:
        r = c.read_holding_registers(0, count=1)
        assert r.isError() and r.exception_code == 6


def test_serve_refuses_a_map_without_a_modbus_server():
    plc = plcrt.load(REACT)
    with pytest.raises(PlcConfigError, match="modbus_map needs"):
        plcrt.serve(plc, lockstep=0, modbus_map={}, start=False)


def test_the_library_map_is_bounded_by_the_cpus_image():
    # a CPU 221 has no analog inputs: no input register at all
    plc = plcrt.load("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD     SM0.0\n"
                     "=      Q0.0\nEND_ORGANIZATION_BLOCK\n", cpu="CPU221")
    with plcrt.serve(plc, modbus=0) as s, \
            ModbusTcpClient("127.0.0.1", port=s.port("modbus"), timeout=5) as c:
        r = c.read_input_registers(0, count=1)
        assert r.isError() and r.exception_code == 2
        assert len(ok(c.read_holding_registers(999, count=1)).registers) == 1


def test_the_server_answers_in_stop_and_the_program_reacts_after_run(served):
    s, c = served
    wait_for(lambda: read(s, "VW2") == 1, what="a first scan")
    s.call(lambda p: p.set_mode("STOP"))
    scans = s.call(lambda p: p.scans)
    ok(c.write_register(0, 9))                        # written while the CPU is stopped
    assert ok(c.read_holding_registers(0, count=1)).registers == [9]
    assert s.call(lambda p: (p.mode, p.scans)) == ("STOP", scans)
    assert read(s, "VW2") == 1                        # the program has not run since
    s.call(lambda p: p.set_mode("RUN"))
    wait_for(lambda: ok(c.read_holding_registers(1, count=1)).registers == [10],
             what="VW2 = VW0 + 1 after RUN")
