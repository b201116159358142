"""Every command-line example of the documentation runs as written.

The examples are the ``console`` and ``sh`` blocks of README.md, docs/*.md
and the READMEs under programs/ and examples/ (``doc_blocks.MARKDOWN``):

* ``console`` blocks: each ``$ command`` runs in bash, from a folder that
  shows the repository's files (so relative paths work and files an
  example writes do not land in the clone), with ``plcrt`` and ``python``
  being this interpreter (``sys.executable -m plcrt``).  Its stdout and
  stderr together, as a terminal would show them, must equal the lines
  after it up to the next ``$``.  Normalisation (``doc_blocks.output_pattern``):
  trailing spaces are ignored, a line ``...`` stands for left-out lines and
  a line ending in ``...`` for a line starting with the text before it.
  ``echo $?`` prints the status of the command before it.
* ``console`` blocks marked ``<!-- debug transcript: plcrt debug ARGS -->``:
  the debugger reads the commands of the transcript's prompts on stdin and
  must print the transcript.
* ``sh`` blocks: the block runs as one ``bash -e`` script in such a folder
  and must succeed without a traceback.

A block that cannot run here says so with ``<!-- not run: REASON -->``.
"""

from __future__ import annotations

import difflib
import os
import subprocess
import sys
from pathlib import Path

import pytest
from doc_blocks import Block, all_blocks, console_steps, matches, mirror, normalise_output

RUN = [b for b in all_blocks("console", "sh") if b.marker != "not run"]
TIMEOUT = 300


def _ids(block: Block) -> str:
    return block.where


@pytest.fixture
def workdir(tmp_path: Path) -> tuple[Path, dict[str, str]]:
    """A folder with a link to every top-level entry of the repository, and
    an environment whose ``plcrt`` and ``python`` are this interpreter."""
    work = tmp_path / "repo"
    work.mkdir()
    mirror(work)
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for name, args in (("plcrt", '-m plcrt "$@"'), ("python", '"$@"')):
        shim = bin_dir / name
        shim.write_text(f'#!/bin/sh\nexec "{sys.executable}" {args}\n', encoding="utf-8")
        shim.chmod(0o755)
    env = {k: v for k, v in os.environ.items()
           if k not in ("FORCE_COLOR", "PY_COLORS", "CLICOLOR_FORCE", "PYTEST_ADDOPTS")
           and not k.startswith(("PLCRT_", "PYTEST_XDIST"))}
    # the disk cache of a fresh install: empty, and the block's own (a
    # program an earlier run marked is native from its first scan)
    env["PLCRT_CACHE_DIR"] = str(tmp_path / "plcrt-cache")
    env.update(PATH=f"{bin_dir}{os.pathsep}{env.get('PATH', '')}", PYTHONUNBUFFERED="1",
               COLUMNS="100", LC_ALL="C.UTF-8", PYTHONIOENCODING="utf-8")
    return work, env


def _bash(script: str, cwd: Path, env: dict[str, str], stdin: str = "",
          *flags: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(["bash", *flags, "-c", script], cwd=cwd, env=env, input=stdin,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          timeout=TIMEOUT)


def _diff(expected: list[str], actual: str) -> str:
    return "\n".join(difflib.unified_diff([ln.rstrip() for ln in expected],
                                          normalise_output(actual).splitlines(),
                                          "documented", "printed", lineterm=""))


@pytest.mark.parametrize("block", [b for b in RUN if b.lang == "console"], ids=_ids)
def test_console_example_prints_what_the_docs_show(block: Block, workdir) -> None:
    work, env = workdir
    if block.marker == "debug transcript":
        commands = [ln.split(") ", 1)[1] for ln in block.lines if ln.startswith("(plcrt")]
        result = _bash(block.marker_arg, work, env, "\n".join(commands) + "\n")
        assert matches(list(block.lines), result.stdout), (
            f"{block.where}: {block.marker_arg}\n{_diff(list(block.lines), result.stdout)}")
        return
    steps = console_steps(block)
    assert steps, f"{block.where}: a console block needs '$ ' commands or a marker"
    status = 0
    for command, expected in steps:
        # `(exit N)` first, so that `echo $?` sees the previous command's status
        result = _bash(f"(exit {status}); {command}", work, env)
        status = result.returncode
        assert "Traceback" not in result.stdout, f"{block.where}: $ {command}\n{result.stdout}"
        assert matches(expected, result.stdout), (
            f"{block.where}: $ {command}\n{_diff(expected, result.stdout)}")


@pytest.mark.parametrize("block", [b for b in RUN if b.lang == "sh"], ids=_ids)
def test_shell_example_runs(block: Block, workdir) -> None:
    work, env = workdir
    result = _bash("\n".join(block.lines), work, env, "", "-e")
    assert result.returncode == 0, f"{block.where}\n{result.stdout}"
    assert "Traceback" not in result.stdout, f"{block.where}\n{result.stdout}"


def test_every_skipped_example_says_why() -> None:
    """A block is left out only with a reason, and only a console block can
    be a debugger transcript."""
    for block in all_blocks("console", "sh", "python"):
        if block.marker == "not run":
            assert len(block.marker_arg) > 10, f"{block.where}: give the reason"
        if block.marker == "debug transcript":
            assert block.lang == "console" and block.marker_arg.startswith("plcrt debug ")


def test_console_blocks_are_commands_or_transcripts() -> None:
    """A console block that is run shows ``$`` commands, or is a marked
    transcript: a block of bare output would otherwise be silently unchecked."""
    for block in RUN:
        if block.lang == "console" and block.marker is None:
            assert block.lines and block.lines[0].startswith("$ "), block.where


def test_the_comparison_can_fail() -> None:
    """The normalisation is narrow: a changed value, a missing or an extra
    line fails; only trailing spaces and the ``...`` forms are forgiven."""
    assert matches(["a  1", "b"], "a  1   \nb\n")
    assert not matches(["a  1", "b"], "a  2\nb\n")
    assert not matches(["a  1", "b"], "a  1\n")
    assert not matches(["a  1"], "a  1\nb\n")
    assert matches(["head", "..."], "head\nx\ny\n")
    assert matches(["head", "...", "tail"], "head\nx\ntail\n")
    assert not matches(["head", "...", "tail"], "head\nx\n")
    assert matches(["sparkline ..."], "sparkline ▁▂▃\n")
    assert not matches(["sparkline ..."], "sparks\n")
