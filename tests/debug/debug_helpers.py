"""Golden transcripts of debugger sessions, shared by the debugger tests.

A transcript is compared with ``tests/debug/golden/<name>.txt``.  After a
deliberate change of the output, regenerate the files with

    PLCRT_UPDATE_GOLDEN=1 .venv/bin/python -m pytest -q tests/debug

and read the diff before keeping it: the golden files are the debugger's
documented behaviour.
"""

from __future__ import annotations

import io
import os
from collections.abc import Sequence
from pathlib import Path

import plcrt
from plcrt.debug import Session

ROOT = Path(__file__).resolve().parents[2]
DATA = Path("tests/debug/data")        # relative to ROOT, so paths in output are stable
GOLDEN = Path(__file__).resolve().parent / "golden"
UPDATE = os.environ.get("PLCRT_UPDATE_GOLDEN") == "1"


def check_golden(name: str, text: str) -> None:
    path = GOLDEN / f"{name}.txt"
    if UPDATE:
        path.write_text(text, encoding="utf-8")
        return
    assert path.exists(), (f"no golden file {path}; create it with PLCRT_UPDATE_GOLDEN=1 "
                           f"and review it")
    assert text == path.read_text(encoding="utf-8"), (
        f"transcript differs from {path.name} (PLCRT_UPDATE_GOLDEN=1 regenerates it)")


def session(program: str | Sequence[str], *, plant: str | None = None, scan_ms: float = 10.0,
            echo: bool = True) -> tuple[Session, io.StringIO]:
    """A session over program file(s) given relative to the repository root
    (the caller must have changed into it)."""
    paths = [program] if isinstance(program, str) else list(program)
    plc = plcrt.load([Path(p) for p in paths], plant=Path(plant) if plant else None,
                     scan_ms=scan_ms, instrument=True)
    out = io.StringIO()
    return Session(plc, out, echo=echo), out


def transcript(program: str | Sequence[str], script: str, **kw: object) -> tuple[str, int]:
    """Run ``script`` (one command a line) and return (output, exit status)."""
    s, out = session(program, **kw)  # type: ignore[arg-type]
    status = s.run(script.strip("\n").splitlines())
    text = out.getvalue()
    assert "Traceback" not in text
    return text, status


def commands(text: str) -> list[tuple[str, str]]:
    """A transcript as (command as echoed without the prompt, its output)."""
    out: list[tuple[str, str]] = []
    for line in text.splitlines(keepends=True):
        if line.startswith("(plcrt"):
            out.append((line.split(") ", 1)[1].rstrip("\n"), ""))
        elif out:
            out[-1] = (out[-1][0], out[-1][1] + line)
    return out


def watch_values(output: str) -> dict[str, str]:
    """address -> value (with ' forced' when marked) from the last watch table."""
    lines = output.splitlines()
    start = max(i for i, ln in enumerate(lines) if ln.split() == ["address", "value"])
    values: dict[str, str] = {}
    for ln in lines[start + 1:]:
        cells = ln.split()
        if len(cells) < 2:
            break
        values[cells[0]] = " ".join(cells[1:])
    return values
