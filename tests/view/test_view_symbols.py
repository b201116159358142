"""``plcrt show --symbols`` names operands as the browser panel does:
``Start_PB:I0.0`` for an address the table names, with or without
``--status``, in LAD and in STL; a timer box is as wide as the name above
it.  The drawings are golden files (``PLCRT_UPDATE_GOLDEN=1`` rewrites them;
review the diff)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from plcrt.cli import main

ROOT = Path(__file__).resolve().parents[2]
GOLDEN = Path(__file__).resolve().parent / "golden"
UPDATE = os.environ.get("PLCRT_UPDATE_GOLDEN") == "1"
LESSON = "examples/course/01-seal-in"
CONVEYOR = "examples/conveyor"


def _show(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
          *argv: str) -> str:
    monkeypatch.chdir(ROOT)
    code = main(["show", *argv])
    out, err = capsys.readouterr()
    assert code == 0, err
    return out


def _golden(name: str, text: str) -> None:
    path = GOLDEN / f"{name}.txt"
    if UPDATE:
        path.write_text(text, encoding="utf-8")
    assert text == path.read_text(encoding="utf-8"), f"drawing differs from {path.name}"


def test_symbols_name_the_operands(capsys: pytest.CaptureFixture[str],
                                   monkeypatch: pytest.MonkeyPatch) -> None:
    out = _show(capsys, monkeypatch, f"{LESSON}/lesson.awl", "--symbols",
                f"{LESSON}/symbols.txt")
    assert "Start_PB:I0.0" in out and "Motor:Q0.0" in out and "Overload_Lamp:Q0.2" in out
    _golden("symbols_lesson1", out)


def test_without_a_table_the_addresses_are_drawn(capsys: pytest.CaptureFixture[str],
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    out = _show(capsys, monkeypatch, f"{LESSON}/lesson.awl")
    assert "Start_PB" not in out and "I0.0" in out


def test_symbols_with_status_boxes_and_stl(capsys: pytest.CaptureFixture[str],
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    args = (f"{CONVEYOR}/conveyor.awl", "--symbols", f"{CONVEYOR}/conveyor_symbols.txt",
            "--data", f"{CONVEYOR}/conveyor.db")
    out = _show(capsys, monkeypatch, *args, "--status", "--scans", "3", "--set", "I0.0=1",
                "--network", "3", "--network", "6")
    assert "Jam_Timer:T37=+0" in out and "Batch_Size:VW100=" in out
    _golden("symbols_conveyor_status", out)
    stl = _show(capsys, monkeypatch, *args, "--stl", "--network", "3")
    assert "LD     Motor:Q0.0" in stl and "TON    Jam_Timer:T37, +30" in stl
