"""The machine exercises of the course (examples/course/07-* on): each
exercise's requirements pass with its reference solution and fail with its
starter, graded the way the panel's *check my program* grades them
(``plcrt.web.course.check``), requirement by requirement.

So the graders are known to pass a right program and not to pass the
starter, which does only part of the job.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

import plcrt
from plcrt.web import course

COURSE = Path(__file__).resolve().parents[2] / "examples" / "course"
SOLUTIONS = COURSE / "solutions"
EXERCISES = sorted(p.name for p in COURSE.iterdir()
                   if p.is_dir() and p.name[:2].isdigit() and (SOLUTIONS / f"{p.name[:2]}.awl").is_file())
MACHINES = {"traffic", "conveyor", "tank", "garage", "elevator"}


def test_every_machine_has_an_exercise() -> None:
    kinds = set()
    for name in EXERCISES:
        kinds |= {m.kind for m in plcrt.load(COURSE / name / "lesson.awl",
                                             plant=COURSE / name / "plant.toml").machines()}
    assert kinds >= MACHINES, f"no exercise for {MACHINES - kinds}"
    assert EXERCISES[0] == "07-traffic-blink" and EXERCISES[-1] == "11-elevator"


@pytest.mark.parametrize("name", EXERCISES)
def test_an_exercise_has_its_files_and_one_docstring_per_requirement(name: str) -> None:
    d = COURSE / name
    for f in ("lesson.awl", "plant.toml", "README.md", "panel.md"):
        assert (d / f).is_file(), f"{name}/{f}"
    les = course.lesson(d)
    assert len(les.tests) == 1 and les.tests[0].name.startswith(f"test_{name[:2]}_")
    tree = ast.parse(les.tests[0].read_text(encoding="utf-8"))
    tests = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name.startswith("test")]
    assert len(tests) >= 3
    for t in tests:
        assert ast.get_docstring(t), f"{name}: {t.name} states no requirement"
    # the page text is for the page: no terminal commands in it
    assert "python -m pytest" not in (d / "panel.md").read_text(encoding="utf-8")


@pytest.mark.parametrize("name", EXERCISES)
def test_the_solution_meets_every_requirement(name: str, monkeypatch) -> None:
    monkeypatch.setenv("PLCRT_EXERCISE_PROGRAM", str(SOLUTIONS / f"{name[:2]}.awl"))
    r = course.check(course.lesson(COURSE / name))
    failed = [(t["doc"], t["message"]) for t in r["tests"] if t["outcome"] != "passed"]
    assert r["ok"] and not failed and r["passed"] >= 3, (failed, r["output"][-3000:])


@pytest.mark.parametrize("name", EXERCISES)
def test_the_starter_fails_a_requirement_and_says_which(name: str, monkeypatch) -> None:
    monkeypatch.delenv("PLCRT_EXERCISE_PROGRAM", raising=False)
    les = course.lesson(COURSE / name)
    r = course.check(les)
    assert not r["ok"] and r["failed"] >= 1 and r["passed"] >= 1, r
    docs = _docs(les.tests[0])
    for t in r["tests"]:
        # each listed as its requirement, not as the function's name
        assert t["doc"] == docs[t["name"]]
        if t["outcome"] == "failed":
            # the failure says what was observed, without pytest's assert rewriting
            assert t["message"] and not t["message"].startswith(("assert", "AssertionError"))
            assert "\nassert " not in t["message"]
    # the first failure's scan trace is in the output the page shows
    assert "PLC trace" in r["output"] and "FAILURES" in r["output"]


def _docs(path: Path) -> dict[str, str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return {n.name: " ".join((ast.get_docstring(n) or "").split("\n\n")[0].split())
            for n in tree.body if isinstance(n, ast.FunctionDef)}


def test_a_run_of_the_whole_course_leaves_the_exercises_out() -> None:
    """The starters fail by design: a run of the whole tree (the project's
    suite) collects the lessons but no exercise; naming an exercise
    collects it."""
    def collected(*args: str) -> str:
        return subprocess.run([sys.executable, "-m", "pytest", "--co", "-q", "-p", "no:cacheprovider",
                               *args], cwd=COURSE.parents[1], capture_output=True, text=True,
                              timeout=120).stdout
    whole = collected("examples/course")
    assert "01-seal-in/test_01_seal_in.py" in whole and "test_07_" not in whole
    one = collected("examples/course/07-traffic-blink")
    assert "test_07_traffic_blink.py::test_the_yellow_light_blinks_at_1_hz" in one


BLINK = """ORGANIZATION_BLOCK MAIN:OB1
TITLE=a blink built from a timer
BEGIN
Network 1
LDN    T37
TON    T37, +{period}
Network 2
LDW<   T37, +{half}
=      Q0.1
END_ORGANIZATION_BLOCK
"""


@pytest.mark.parametrize("period, half, ok", [(10, 5, True), (20, 10, False), (10, 2, False)])
def test_the_blink_grader_judges_the_light_not_the_program(period, half, ok, tmp_path,
                                                           monkeypatch) -> None:
    """Another right program (a timer that restarts itself, 1 Hz) passes;
    0.5 Hz, or 1 Hz with 0.2 s on, fails the 1 Hz requirement with the
    times it saw."""
    prog = tmp_path / "blink.awl"
    prog.write_text(BLINK.format(period=period, half=half), encoding="utf-8")
    monkeypatch.setenv("PLCRT_EXERCISE_PROGRAM", str(prog))
    r = course.check(course.lesson(COURSE / "07-traffic-blink"))
    failed = {t["name"]: t["message"] for t in r["tests"] if t["outcome"] != "passed"}
    if ok:
        assert r["ok"] and not failed, failed
    else:
        assert list(failed) == ["test_the_yellow_light_blinks_at_1_hz"]
        assert "(off at 0.00 s, on at 0.01 s, off at " in failed["test_the_yellow_light_blinks_at_1_hz"]
