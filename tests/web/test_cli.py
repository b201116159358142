"""``plcrt serve`` as a command: the address it prints, the warning off
loopback, Ctrl-C, and errors without a traceback."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
LESSON = REPO / "examples" / "course" / "01-seal-in"


def _start(*args: str, **env: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "plcrt", "serve", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            cwd=REPO, env={**os.environ, "PLCRT_BACKEND": "python", **env})


def _address(proc: subprocess.Popen) -> str:
    line = proc.stdout.readline()
    assert line.startswith("plcrt panel: http://"), line
    return line.split()[2]


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT to a child")
def test_serve_prints_its_address_warns_off_loopback_and_stops_on_ctrl_c() -> None:
    proc = _start(str(LESSON), "--port", "0", "--host", "0.0.0.0")
    try:
        url = _address(proc)
        port = int(url.rsplit(":", 1)[1].strip("/"))
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=10) as r:
            assert r.status == 200 and b"<!DOCTYPE html>" in r.read(200)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=20)
    finally:
        proc.kill()
    assert proc.returncode == 0
    assert "warning: listening on 0.0.0.0: anyone who can reach this address" in err
    assert "Traceback" not in err


def test_serve_on_loopback_says_nothing_more() -> None:
    proc = _start(str(LESSON), "--port", "0")
    try:
        _address(proc)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=20)
    finally:
        proc.kill()
    assert proc.returncode == 0 and err == ""


def test_a_busy_port_is_a_clear_error() -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        proc = _start(str(LESSON), "--port", str(port))
        out, err = proc.communicate(timeout=30)
    assert proc.returncode == 1
    assert f"cannot listen on 127.0.0.1:{port}" in err and "Traceback" not in err


def test_a_program_that_does_not_load_is_reported_like_check(tmp_path) -> None:
    bad = tmp_path / "bad.awl"
    bad.write_text("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\nFOO Q0.0\n"
                   "END_ORGANIZATION_BLOCK\n", encoding="utf-8")
    proc = _start(str(bad), "--port", "0")
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 1
    assert "bad.awl:5" in err and "FOO" in err and "Traceback" not in err
    assert out == ""


def test_open_hands_the_address_to_the_browser(tmp_path) -> None:
    """--open starts the user's browser ($BROWSER here: a script that
    writes down the address it is given)."""
    got = tmp_path / "url.txt"
    script = "import sys; open(sys.argv[2], 'w').write(sys.argv[1])"
    browser = f'{sys.executable} -c "{script}" %s {got}'
    proc = _start(str(LESSON), "--port", "0", "--open", BROWSER=browser)
    try:
        url = _address(proc)
        for _ in range(100):
            if got.is_file() and got.read_text():
                break
            time.sleep(0.1)
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=20)
    finally:
        proc.kill()
    assert got.read_text() == url
