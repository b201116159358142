"""A CPU port on a pseudo-terminal (plcrt.net.serial): pymodbus's serial
client, a real Modbus RTU master, talks to the program's own MBUS_INIT /
MBUS_SLAVE through /dev/pts/N, and a terminal program to its freeport
protocol; characters are paced at the port's baud rate in simulated time
(docs/network.md, "Serial ports on a pseudo-terminal")."""

from __future__ import annotations

import os
import sys
import time

import pytest

if not sys.platform.startswith("linux"):
    pytest.skip("pseudo-terminals as /dev/pts/N are Linux's", allow_module_level=True)
pytest.importorskip("pymodbus")
serial = pytest.importorskip("serial")
from pymodbus.client import ModbusSerialClient  # noqa: E402

import plcrt  # noqa: E402
from plcrt.devices.modbus.slavelib import slave_of  # noqa: E402
from plcrt.errors import PlcConfigError  # noqa: E402
from plcrt.net.serial import pty_path  # noqa: E402

from .modbus_net_helpers import ECHO, SLAVE, wait_for  # noqa: E402


def ok(r):
    assert not r.isError(), r
    return r


def slave(baud: int, parity: int):
    plc = plcrt.load(SLAVE.format(baud=baud, parity=parity))
    s = plcrt.serve(plc, serial={0: "pty"})
    wait_for(lambda: s.call(lambda p: slave_of(p).enabled), what="MBUS_INIT")
    return s


def test_pymodbus_serial_master_talks_to_the_programs_mbus_slave():
    # the program's even parity: a pseudo-terminal keeps none, the master
    # is set to none and its characters take the port's parity
    with slave(19200, 2) as s:
        path = pty_path(s, 0)
        assert path.startswith("/dev/") and os.path.exists(path)
        c = ModbusSerialClient(path, baudrate=19200, timeout=2, retries=0)
        assert c.connect()
        try:
            ok(c.write_register(0, 1234, device_id=3))         # 40001 = VW1000
            assert s.call(lambda p: p.read("VW1000")) == 1234
            wait_for(lambda: ok(c.read_holding_registers(0, count=2, device_id=3)).registers
                     == [1234, 1235], what="VW1002 = VW1000 + 1")
            ok(c.write_coils(8, [True] * 8, device_id=3))       # Q1.0 .. Q1.7
            assert s.call(lambda p: p.read("QB1")) == 0xFF
            assert ok(c.read_coils(8, count=8, device_id=3)).bits == [True] * 8
            r = c.read_holding_registers(9, count=2, device_id=3)   # MaxHold 10
            assert r.isError() and r.exception_code == 2
            assert s.call(lambda p: p.read("MB2")) == 9             # the library's Error 9
        finally:
            c.close()


def test_characters_are_paced_at_the_ports_baud_rate():
    """1200 baud 8E1 (11 bits a character): a read of 10 registers is 8
    characters out and 25 back; the answer leaves over exactly
    ceil(25 * 11 / 1200 s) of simulated time, and real time follows it."""
    with slave(1200, 2) as s:
        c = ModbusSerialClient(pty_path(s), baudrate=1200, timeout=3, retries=0)
        assert c.connect()
        try:
            t0 = time.monotonic()
            ok(c.read_holding_registers(0, count=10, device_id=3))
            wall = time.monotonic() - t0
        finally:
            c.close()
        rec = s.call(lambda p: slave_of(p).log[-1])
    assert rec["answer_end"] - rec["served"] == -(-25 * 11 * 1_000_000 // 1200)
    assert rec["last_char"] - rec["first_char"] == -(-7 * 11 * 1_000_000 // 1200)
    assert wall >= (8 + 25) * 11 / 1200                   # 0.3025 s on the line


def test_a_master_at_another_rate_is_garbled_as_on_a_line():
    with slave(19200, 0) as s:
        c = ModbusSerialClient(pty_path(s), baudrate=9600, timeout=0.5, retries=0)
        assert c.connect()
        try:
            r = c.read_holding_registers(0, count=1, device_id=3)
        except Exception as e:  # pymodbus raises or returns an error for no answer
            r = e
        finally:
            c.close()
        assert getattr(r, "isError", lambda: True)()
        wait_for(lambda: s.call(lambda p: [x["error"] for x in slave_of(p).log]) == [6],
                 what="the library's receive error (Error 6)")


def test_the_programs_freeport_protocol_on_a_terminal():
    plc = plcrt.load(ECHO)
    with plcrt.serve(plc, serial={0: "pty"}) as s:
        wait_for(lambda: s.call(lambda p: p.scans) > 1, what="the first scan")
        with serial.Serial(pty_path(s), 9600, timeout=2) as line:
            for ch in b"S7":
                line.write(bytes((ch,)))
                assert line.read(1) == bytes((ch,))
        assert s.call(lambda p: p.read("VW200")) == 2


def test_serial_specs_that_cannot_be_served_are_config_errors():
    plc = plcrt.load(ECHO)
    for spec, match in (({0: "tcp"}, "only \"pty\""), ({2: "pty"}, "no port 2"),
                        ("pty", "a mapping"), ({True: "pty"}, "no port")):
        with pytest.raises(PlcConfigError, match=match):
            plcrt.serve(plc, serial=spec, start=False)
    plant = "[port.0.modbus_slave]\naddress = 1\n"
    busy = plcrt.load(ECHO, plant=plant)
    with pytest.raises(PlcConfigError, match="device of the plant file"):
        plcrt.serve(busy, serial={0: "pty"}, start=False)
    with plcrt.serve(plc, serial={1: "pty"}) as s, pytest.raises(PlcConfigError):
        pty_path(s, 0)
