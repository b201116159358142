"""The course's lessons in the panel: the page text of every lesson (steps
for the page, its input table), the Markdown reader's safe structure."""

from __future__ import annotations

import pytest

from plcrt.errors import PlcConfigError
from plcrt.web import course, markdown
from plcrt.web.present import INPUT_KINDS

from .conftest import REPO

LESSONS = course.lessons(REPO / "examples/course")


def test_the_course_has_its_six_lessons_and_five_exercises() -> None:
    assert [le.id[:2] for le in LESSONS] == [f"{n:02d}" for n in range(1, 12)]


@pytest.mark.parametrize("les", LESSONS, ids=lambda le: le.id)
def test_every_lesson_has_steps_for_the_page_and_kinds_for_its_inputs(les) -> None:
    """The page shows panel.md, not the terminal README: steps with the
    page's controls, no shell commands; its input table names a kind for
    every input the program uses, but those a machine of the plant drives
    (its sensors, and its buttons on its drawing)."""
    import plcrt
    from plcrt.web.present import io_bits
    assert (les.dir / "panel.md").is_file()
    doc = les.page()
    text = markdown.plain_text(doc)
    assert "Run these from the repository root" not in text and "plcrt run" not in text
    assert "Click **Run**" in les.text() and "Check my program" in text
    assert any("ol" in b for b in doc)                      # numbered steps
    kinds = les.kinds()
    assert set(kinds.values()) <= set(INPUT_KINDS)
    plc = plcrt.load(str(les.program), symbols=str(les.symbols) if les.symbols else None,
                     plant=str(les.plant) if les.plant else None)
    wired = {a for m in plc.machines() for a in m.wiring().values() if a}
    assert set(io_bits(plc)[0]) - wired == set(kinds)


def test_lesson_1_declares_the_normally_closed_stop_button() -> None:
    les = course.find(LESSONS, "01-seal-in")
    assert les.kinds() == {"I0.0": "button", "I0.1": "button_nc", "I0.2": "switch_nc"}


def test_an_unknown_kind_in_the_input_table_is_an_error(tmp_path) -> None:
    import shutil
    folder = tmp_path / "01-x"
    shutil.copytree(REPO / "examples/course/01-seal-in", folder)
    (folder / "panel.md").write_text("| input | kind |\n|---|---|\n| I0.1 | toggle |\n")
    with pytest.raises(PlcConfigError, match="kind 'toggle' is not one of switch"):
        course.lesson(folder).kinds()


def test_emphasis_code_and_links_become_spans() -> None:
    spans = markdown.inline("a **bold** and *it* `c` [site](https://example.org/x) "
                            "[file](lesson.awl)", local=lambda u: f"lesson/{u}")
    assert spans == [
        {"t": "a "}, {"t": "bold", "b": True}, {"t": " and "}, {"t": "it", "i": True},
        {"t": " "}, {"t": "c", "code": True}, {"t": " "},
        {"t": "site", "href": "https://example.org/x"}, {"t": " "},
        {"t": "file", "href": "lesson/lesson.awl"}]


@pytest.mark.parametrize("url", ["javascript:alert%281%29", "JaVaScRiPt:x", "data:text/html,x",
                                 "//evil.example/x", "/etc/passwd", "vbscript:x",
                                 "https://", "file:///etc/passwd"])
def test_links_other_than_http_and_lesson_files_keep_only_their_words(url: str) -> None:
    spans = markdown.inline(f"[words]({url})", local=lambda u: None)
    assert spans == [{"t": "words"}]


def test_a_relative_link_is_kept_only_to_a_file_of_the_lessons_folder() -> None:
    les = course.find(LESSONS, "01-seal-in")
    doc = markdown.parse("[p](lesson.awl) [r](../02-timers/README.md) [x](missing.awl)",
                         les._link)
    assert doc == [{"p": [{"t": "p", "href": "lesson/lesson.awl"}, {"t": " "}, {"t": "r"},
                          {"t": " "}, {"t": "x"}]}]


def test_blocks_headings_lists_code_and_tables() -> None:
    doc = markdown.parse("# Title\n\nSome *text*\non two lines.\n\n1. first\n   more\n"
                         "2. second\n\n```sh\n<b>x</b>\n```\n\n| a | b |\n|---|---|\n"
                         "| `1` | 2 |\n- item\n<!-- hidden -->\n")
    assert doc == [
        {"h": 1, "s": [{"t": "Title"}]},
        {"p": [{"t": "Some "}, {"t": "text", "i": True}, {"t": " on two lines."}]},
        {"ol": [[{"t": "first more"}], [{"t": "second"}]]},
        {"pre": "<b>x</b>"},
        {"table": {"head": [[{"t": "a"}], [{"t": "b"}]],
                   "rows": [[[{"t": "1", "code": True}], [{"t": "2"}]]]}},
        {"ul": [[{"t": "item"}]]},
    ]


def test_a_numbered_list_split_by_a_code_block_goes_on_counting() -> None:
    doc = markdown.parse("1. one\n\n   ```sh\n   x\n   ```\n\n2. two\n")
    assert doc == [{"ol": [[{"t": "one"}]]}, {"pre": "x"},
                   {"ol": [[{"t": "two"}]], "start": 2}]


def test_a_huge_text_is_cut() -> None:
    doc = markdown.parse("word " * (markdown.MAX_CHARS // 2))
    assert "cut after" in doc[-1]["p"][0]["t"]
    assert sum(len(s["t"]) for b in doc for s in b["p"]) < markdown.MAX_CHARS + 100


def test_check_lists_requirements_and_keeps_the_first_failure(tmp_path) -> None:
    """A test is listed by its docstring's first paragraph (by its name in
    words without one, with its parameters); a failure by its assertion's
    own message; a long output keeps its start and its end."""
    from plcrt.web.course import OUTPUT_CHARS, _clip, _docs, _message
    f = tmp_path / "test_x.py"
    f.write_text('def test_a():\n    """The lamp is lit\n    at 1 s.\n\n    More."""\n\n'
                 'def test_b_no_doc():\n    pass\n')
    assert _docs([f]) == {"test_a": "The lamp is lit at 1 s."}
    assert _message("AssertionError: the lamp was dark at 1.00 s\nassert 0 == 1") == \
        "the lamp was dark at 1.00 s"
    assert _message("AssertionError: assert 0 == 1\n +  where 0 = f()") == \
        "assert 0 == 1\n +  where 0 = f()"
    out = _clip("FIRST failure" + "x" * (3 * OUTPUT_CHARS) + "summary")
    assert out.startswith("FIRST failure") and out.endswith("summary")
    assert len(out) < OUTPUT_CHARS + 100
