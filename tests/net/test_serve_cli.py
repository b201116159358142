"""``plcrt serve`` with network servers: headless (``--no-panel``) and beside
the panel, each listening where it says, on loopback by default; Ctrl-C
ends it with status 0; bad options are errors, never tracebacks."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from plcrt.cli import main
from plcrt.net.client import LockstepClient

from .modbus_net_helpers import ECHO

COUNT = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD SM0.0
+I 1, VW0
END_ORGANIZATION_BLOCK
"""


def _start(args: list[str], tmp_path: Path) -> tuple[subprocess.Popen, dict[str, int]]:
    prog = tmp_path / "count.awl"
    prog.write_text(COUNT)
    p = subprocess.Popen([sys.executable, "-m", "plcrt", "serve", str(prog), *args],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    ports: dict[str, int] = {}
    deadline = time.monotonic() + 60
    assert p.stdout is not None
    while time.monotonic() < deadline:
        line = p.stdout.readline()
        if not line:
            break
        m = re.match(r"plcrt (\w+) server: 127\.0\.0\.1:(\d+)", line)
        if m:
            ports[m.group(1)] = int(m.group(2))
        if line.startswith("(Ctrl-C") or line.startswith("plcrt panel:"):
            return p, ports
    p.kill()
    pytest.fail(f"plcrt serve did not start: {p.stderr.read() if p.stderr else ''}")


def _stop(p: subprocess.Popen) -> int:
    p.send_signal(signal.SIGINT)
    try:
        return p.wait(20)
    finally:
        if p.poll() is None:
            p.kill()


def test_headless_lockstep_server_steps_the_program(tmp_path: Path) -> None:
    p, ports = _start(["--no-panel", "--lockstep", "0", "--speed", "lockstep"], tmp_path)
    try:
        with LockstepClient("127.0.0.1", ports["lockstep"]) as c:
            assert c.advance(seconds="1s") == 100
            assert c.read("VW0") == {"VW0": 100}
    finally:
        assert _stop(p) == 0


def test_beside_the_panel_the_program_runs_in_real_time(tmp_path: Path) -> None:
    p, ports = _start(["--port", "0", "--lockstep", "0"], tmp_path)
    try:
        with LockstepClient("127.0.0.1", ports["lockstep"]) as c:
            assert c.hello()["speed"] == "panel"
            first = c.read("VW0")["VW0"]
            time.sleep(0.3)
            assert c.read("VW0")["VW0"] > first      # the panel's thread scans it
    finally:
        assert _stop(p) == 0


@pytest.mark.parametrize("args, message", [
    (["--no-panel"], "name a server"),
    (["--no-panel", "--lockstep", "70000"], "outside 0..65535"),
    (["--no-panel", "--lockstep", "a:b:c"], "[HOST:]PORT"),
    (["--no-panel", "--lockstep", "0", "--speed", "warp"], "speed"),
    (["--no-panel", "--lockstep", "0", "--allow-writes", "VB9-MB2"], "two areas"),
    (["--no-panel", "--lockstep", "0", "--max-connections", "0"], "max_connections"),
])
def test_bad_options_are_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                args: list[str], message: str) -> None:
    prog = tmp_path / "count.awl"
    prog.write_text(COUNT)
    assert main(["serve", str(prog), *args]) == 1
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_a_cpu_port_on_a_pseudo_terminal_from_the_command_line(tmp_path: Path) -> None:
    serial = pytest.importorskip("serial")
    prog = tmp_path / "echo.awl"
    prog.write_text(ECHO)
    p = subprocess.Popen([sys.executable, "-m", "plcrt", "serve", str(prog), "--no-panel",
                          "--serial", "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True)
    try:
        assert p.stdout is not None
        line = p.stdout.readline()
        m = re.match(r"plcrt port 0: (/dev/\S+)$", line.strip())
        assert m, line + (p.stderr.read() if p.poll() is not None and p.stderr else "")
        with serial.Serial(m.group(1), 9600, timeout=3) as tty:
            time.sleep(0.2)                      # the program's first scan set freeport
            echoed = b""
            for ch in (b"p", b"l", b"c"):      # one at a time: an XMT still sending
                tty.write(ch)                  # would not take the next echo
                echoed += tty.read(1)
            assert echoed == b"plc"
    finally:
        assert _stop(p) == 0


def test_a_modbus_map_needs_a_modbus_server(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    prog = tmp_path / "count.awl"
    prog.write_text(COUNT)
    assert main(["serve", str(prog), "--no-panel", "--lockstep", "0",
                 "--modbus-map", "x.toml"]) == 1
    assert "--modbus-map needs a Modbus server" in capsys.readouterr().err


def test_s7_and_modbus_clients_beside_the_panel(tmp_path: Path) -> None:
    """`plcrt serve PROGRAM --s7 0 --modbus 0`: python-snap7 and pymodbus
    read the running program (VW0 counts scans) through the panel's thread."""
    from pymodbus.client import ModbusTcpClient

    from .s7_support import connect
    p, ports = _start(["--port", "0", "--s7", "0", "--modbus", "0"], tmp_path)
    try:
        s7 = connect(ports["s7"])
        try:
            first = int.from_bytes(s7.db_read(1, 0, 2), "big")
            time.sleep(0.2)
            assert int.from_bytes(s7.db_read(1, 0, 2), "big") > first
        finally:
            s7.disconnect()
        mb = ModbusTcpClient("127.0.0.1", port=ports["modbus"], timeout=5)
        assert mb.connect()
        try:
            r = mb.read_holding_registers(0, count=1)     # 40001 = VW0
            assert not r.isError() and r.registers[0] > first
        finally:
            mb.close()
    finally:
        assert _stop(p) == 0
