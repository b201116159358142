"""The course's exercises (07 on) grade the student's ``lesson.awl``,
which starts unfinished: their tests run when the run names the exercise
(its folder or a test file of it, as the panel's *check my program* and
the exercise README do), not in a run of the whole tree, where the
starters would fail by design.  An exercise is a lesson folder whose
number has a reference solution in ``solutions/NN.awl``;
``tests/course/test_exercises.py`` grades each against its solution and
its starter.
"""

from __future__ import annotations

from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
SOLUTIONS = HERE / "solutions"


def _exercise(path: Path) -> Path | None:
    """The exercise folder ``path`` lies in, or None."""
    try:
        rel = path.resolve().relative_to(HERE)
    except ValueError:
        return None
    if not rel.parts:
        return None
    folder = rel.parts[0]
    if (SOLUTIONS / f"{folder[:2]}.awl").is_file() and folder[:2].isdigit():
        return HERE / folder
    return None


def pytest_ignore_collect(collection_path: Path, config: pytest.Config) -> bool | None:
    ex = _exercise(collection_path)
    if ex is None:
        return None
    base = config.invocation_params.dir
    for arg in config.args:
        named = (base / arg.split("::")[0]).resolve()
        if named == ex or ex in named.parents:
            return None
    return True
