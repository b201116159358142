"""The marks of programs whose machine code is on disk (plcrt/compiler/tiermarks.py).

A mark lives in the native disk cache's folder, as one of its entries (so
the cache's size limit and trimming cover it), is found without importing
the native backend, and is never made for a key that only this process
can know.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from plcrt.compiler import tiermarks
from plcrt.compiler.cache import program_key, with_options
from plcrt.compiler.native import diskcache
from plcrt.engine.runtime import parse_sources

PROGRAM = "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\n= Q0.0\nEND_ORGANIZATION_BLOCK\n"


def _key(**options: object) -> tuple:
    return program_key(parse_sources(PROGRAM), cpu="CPU 224XP",
                       **{"symbols": None, "backend": "native", **options})


@pytest.mark.parametrize("where", ["env", "home"])
def test_the_marks_folder_is_the_disk_cache_folder(where: str, tmp_path: Path,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    if where == "env":
        monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path / "c"))
    else:
        monkeypatch.delenv("PLCRT_CACHE_DIR", raising=False)
        monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert Path(tiermarks._folder()) == diskcache.cache_dir()


def test_a_mark_is_a_disk_cache_entry_found_by_its_program_key(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path))
    key = _key()
    assert not tiermarks.marked(key)
    assert tiermarks.mark(key)
    assert tiermarks.marked(key)
    # another option value is another program build: not marked
    assert not tiermarks.marked(with_options(key, backend="python"))
    assert not tiermarks.marked(_key(instrument=True))
    # the mark is an entry of the disk cache: checked and trimmed with it
    name = tiermarks.mark_key(key)
    assert diskcache.load(name) is not None
    diskcache.trim(0)
    assert not tiermarks.marked(key)


def test_no_mark_when_the_cache_keeps_nothing_or_the_key_is_this_process_s(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path))
    key = _key()
    assert tiermarks.mark(key)
    monkeypatch.setenv("PLCRT_NATIVE_CACHE_MB", "0")
    assert not tiermarks.marked(key)          # a mark left from before means nothing
    monkeypatch.delenv("PLCRT_NATIVE_CACHE_MB")
    unpicklable = _key(plant=lambda: None)    # fingerprinted by identity
    assert tiermarks.mark_key(unpicklable) is None
    assert not tiermarks.mark(unpicklable) and not tiermarks.marked(unpicklable)


def test_with_options_is_program_key_with_those_options() -> None:
    program = parse_sources(PROGRAM)
    base = dict(cpu="CPU 224XP", symbols=None, instrument=False, backend="native")
    assert with_options(program_key(program, **base), backend="python") == \
        program_key(program, **{**base, "backend": "python"})


@pytest.mark.parametrize("raw", ["", "0", "0.0", " 0 ", "1e-9", "0.5", "256", "-1", "nan",
                                 "abc", "1e40"])
def test_a_mark_is_ignored_exactly_when_the_cache_keeps_nothing(
        raw: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PLCRT_NATIVE_CACHE_MB", raw)
    assert tiermarks._limit_is_zero() == (diskcache.limit_bytes() == 0)
