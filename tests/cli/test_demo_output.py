"""What ``make demo`` prints reads as a demo, not as failures: every demo
command succeeds, and every notice on stderr is one short line; a library's
emulation notice points to its docs for the details."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from plcrt.cli import main

ROOT = Path(__file__).resolve().parents[2]

#: the longest message of a notice, without its file:line: prefix and network
MAX_NOTICE = 160


def _demo_commands() -> list[list[str]]:
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    recipe = makefile.split("\ndemo:", 1)[1].split("\n\n", 1)[0]
    return [shlex.split(line.strip())[1:] for line in recipe.splitlines()
            if line.strip().startswith("$(BIN)/plcrt ")]


DEMO = _demo_commands()


def test_the_demo_has_commands() -> None:
    assert len(DEMO) >= 5


@pytest.mark.parametrize("argv", DEMO, ids=[" ".join(a[:2]) for a in DEMO])
def test_demo_command_prints_short_notices(argv: list[str], capsys: pytest.CaptureFixture[str],
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 0, err
    for line in err.splitlines():
        message = re.sub(r"^\S+:\d+:\d+: (warning|note|error): ", "", line)
        message = re.sub(r" \[[A-Z]+\d+ network \d+\]$", "", message)
        assert len(message) <= MAX_NOTICE, f"a long notice: {line}"
        if "emulated" in message:
            assert re.search(r"\(docs/[\w-]+\.md\)$", message), line
