"""Program text is untrusted: titles, operands and symbol names reach the
terminal as text, never as rich markup or raw control characters.

A network title can hold rich markup (``[bold red]x[/]``, ``[link=...]``)
or an ANSI escape sequence (``\\x1b[2J`` clears the screen); an operand can
hold any character that is not a blank, a comma, a semicolon or a quote.
``plcrt show`` must print such text as it is written, with control
characters escaped, in plain and in coloured output.
"""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from rich.console import Console

from plcrt.cli import main
from plcrt.engine.runtime import parse_sources
from plcrt.view.render import render_program

ROOT = Path(__file__).resolve().parents[2]

ESC = "\x1b[2J"
OSC_LINK = "\x1b]8;;http://evil\x1b\\link\x1b]8;;\x1b\\"
PROGRAM = (
    "ORGANIZATION_BLOCK MAIN:OB1\n"
    f"TITLE=Block [link=file:///etc/passwd]click[/link] {ESC} bell\x07\n"
    "BEGIN\n"
    f"Network 1 // [bold red]x[/] title {ESC}{OSC_LINK}\tend\n"
    f"LD     Start{ESC}\n"
    "=      Q0.0\n"
    "Network 2 // [red]\n"
    "LD     I0.0\n"
    "CALL   \x1b]0pwned\x07\n"
    "END_ORGANIZATION_BLOCK\n"
)


@pytest.fixture
def program_file(tmp_path: Path) -> Path:
    path = tmp_path / "inject.awl"
    path.write_text(PROGRAM, encoding="utf-8")
    return path


def test_show_prints_markup_literally_and_escapes_controls(
        program_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", str(program_file)]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    # no control character of the program reaches the output
    assert not any(ord(c) < 32 and c != "\n" or 0x7f <= ord(c) < 0xa0 for c in out)
    lines = out.splitlines()
    assert lines[0] == ("OB1 (MAIN)  Block [link=file:///etc/passwd]click[/link] "
                        "\\x1b[2J bell\\x07")
    assert ("Network 1  [bold red]x[/] title \\x1b[2J\\x1b]8;;http://evil\\x1b\\link"
            "\\x1b]8;;\\x1b\\ end") in lines
    assert "Network 2  [red]" in lines
    assert "Start\\x1b[2J" in out           # the operand above its contact
    assert "\\x1b]0pwned\\x07" in out      # the CALL box title


def test_styled_rendering_keeps_program_text_plain(program_file: Path) -> None:
    # On a terminal the drawing is coloured: the only escape sequences are
    # the view's own styles, and markup in titles is not interpreted.
    texts = render_program(parse_sources(program_file), styled=True)
    buf = io.StringIO()
    console = Console(file=buf, force_terminal=True, color_system="truecolor",
                      highlight=False, soft_wrap=True, width=200)
    for text in texts:
        console.print(text)
    out = buf.getvalue()
    assert "[bold red]x[/]" in out and "[link=file:///etc/passwd]click[/link]" in out
    assert "\x1b]8;" not in out               # no hyperlink made from the markup
    assert ESC not in out and "\x07" not in out
    plain = "".join(t.plain for t in texts)
    assert "\x1b" not in plain and "\\x1b[2J" in plain


def test_box_width_counts_the_escaped_operand(program_file: Path) -> None:
    # The CALL box is wide enough for its escaped title (its right side
    # stays in line with the top corner).
    texts = render_program(parse_sources(program_file), styled=False)
    rows = texts[-1].plain.splitlines()
    top = next(r for r in rows if "┌" in r)
    title = next(r for r in rows if "pwned" in r)
    assert top.index("┐") == title.rindex("│")


def test_show_empty_file_says_there_is_nothing_to_show(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    empty = tmp_path / "empty.awl"
    empty.write_text("// only a comment\n", encoding="utf-8")
    assert main(["show", str(empty)]) == 1
    out, err = capsys.readouterr()
    assert out == ""
    assert err == (f"plcrt: error: nothing to show: {empty} holds no block (an empty file, "
                   f"or only comments)\n")


def test_show_network_allows_blanks_around_the_slash(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    # as the debugger's `break SCALE / 2`
    monkeypatch.chdir(ROOT)
    assert main(["show", "programs/subroutine.awl", "--network", "SCALE / 2"]) == 0
    out, _ = capsys.readouterr()
    assert "Network 2  A negative raw value" in out and "Network 1" not in out


@pytest.mark.parametrize("text, shown", [
    ("Motor 1 – Förderband 电机", "Motor 1 – Förderband 电机"),   # letters of any script stay
    ("a\tb", "a b"),
    ("\x1b[2J", "\\x1b[2J"),
    ("bell\x07 del\x7f c1\x9b", "bell\\x07 del\\x7f c1\\x9b"),
    ("line\nbreak\r", "line\\x0abreak\\x0d"),
    ("abc\u202edcba", "abc\\u202edcba"),                          # bidi override
    ("bad byte \udcff", "bad byte \\udcff"),                       # surrogateescape
])
def test_printable(text: str, shown: str) -> None:
    from plcrt.safetext import printable
    assert printable(text) == shown
