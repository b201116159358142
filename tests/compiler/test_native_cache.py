"""The native backend's machine code at size: compiled module by module and
linked, and kept in a disk cache that is atomic, checked, keyed by
llvmlite and the host CPU, bounded in size and safe for processes that
write one entry at once (plcrt/compiler/native/diskcache.py, jit.py).
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

import plcrt
from plcrt.compiler.cache import programs as program_cache
from plcrt.compiler.native import diskcache

AREAS = ("I", "Q", "M", "V", "SM", "S", "TV", "TB", "CV", "CB", "AC")


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("PLCRT_NATIVE_CACHE_MB", raising=False)
    return tmp_path / "native"


# -- the file format ----------------------------------------------------------

def test_objects_come_back_as_stored_and_a_hit_marks_the_file_used(cache) -> None:
    key = diskcache.make_key(["ir", "llvmlite 1", "cpu"])
    objects = [b"\x7fELF one", b"", bytes(range(256)) * 10]
    assert diskcache.load(key) is None
    assert diskcache.store(key, objects) is True
    path = cache / f"{key}.native"
    os.utime(path, (1_000_000, 1_000_000))
    assert diskcache.load(key) == objects
    assert path.stat().st_mtime > 1_000_000          # touched: least recently used last


@pytest.mark.parametrize("damage", ["torn", "flipped", "foreign", "empty", "count"])
def test_a_damaged_file_is_a_miss_never_code(cache, damage) -> None:
    key = diskcache.make_key(["prog"])
    diskcache.store(key, [b"A" * 1000, b"B" * 10])
    path = cache / f"{key}.native"
    data = path.read_bytes()
    bad = {"torn": data[:len(data) // 2],
           "flipped": data[:-1] + bytes([data[-1] ^ 1]),
           "foreign": b"\x7fELF" + data[4:],
           "empty": b""}
    if damage == "count":       # a checksum that matches a table out of bounds
        import hashlib
        head = len(diskcache._MAGIC) + 64
        body = (10**6).to_bytes(4, "little") + data[head + 4:]
        bad["count"] = diskcache._MAGIC + hashlib.sha256(body).hexdigest().encode() + body
    path.write_bytes(bad[damage])
    assert diskcache.load(key) is None


def test_the_key_depends_on_every_part_and_their_boundaries() -> None:
    k = diskcache.make_key
    assert k(["ab", "c"]) != k(["a", "bc"])
    assert k(["ir", "0.50.0", "x86_64", "znver3"]) != k(["ir", "0.50.0", "x86_64", "skylake"])
    assert k(["ir", "0.50.0"]) != k(["ir", "0.51.0"])
    with pytest.raises(ValueError):
        diskcache._path("../x")


# -- the size bound -------------------------------------------------------------

def test_the_folder_is_trimmed_least_recently_used_first(cache, monkeypatch) -> None:
    monkeypatch.setenv("PLCRT_NATIVE_CACHE_MB", str(10_000 / 2**20))   # 10 000 bytes
    keys = [diskcache.make_key([str(i)]) for i in range(4)]
    for i, key in enumerate(keys[:3]):
        diskcache.store(key, [bytes([i]) * 3000])
        os.utime(cache / f"{key}.native", (1000 + i, 1000 + i))
    assert diskcache.load(keys[0]) is not None      # used now: the newest
    diskcache.store(keys[3], [b"x" * 3000])        # 4 x 3 KiB > 10 000 bytes
    left = {p.name.split(".")[0] for p in cache.glob("*.native")}
    assert left == {keys[0], keys[2], keys[3]}      # keys[1] was the least recently used
    assert sum(p.stat().st_size for p in cache.glob("*.native")) <= 10_000


def test_the_limit_comes_from_the_environment(cache, monkeypatch) -> None:
    assert diskcache.limit_bytes() == diskcache.DEFAULT_LIMIT_MB * 2**20 == 256 * 2**20
    monkeypatch.setenv("PLCRT_NATIVE_CACHE_MB", "64")
    assert diskcache.limit_bytes() == 64 * 2**20
    for junk in ("lots", "-5", "nan"):
        monkeypatch.setenv("PLCRT_NATIVE_CACHE_MB", junk)
        assert diskcache.limit_bytes() == 256 * 2**20, junk
    monkeypatch.setenv("PLCRT_NATIVE_CACHE_MB", "0")       # keep nothing
    key = diskcache.make_key(["p"])
    assert diskcache.store(key, [b"code"]) is False
    assert diskcache.load(key) is None and not list(cache.glob("*.native"))


def test_a_writers_leftover_is_removed_only_when_stale_and_old_files_go(cache) -> None:
    cache.mkdir(parents=True)
    old, new = cache / "abc.1.2.xyz.tmp", cache / "abd.1.3.xyz.tmp"
    old.write_bytes(b"half")
    new.write_bytes(b"half")
    os.utime(old, (time.time() - 2 * diskcache.STALE_TMP_S,) * 2)
    legacy = cache / ("ab" * 20 + ".o")             # an older plcrt's entry
    legacy.write_bytes(b"plcrt-native-1\n")
    diskcache.trim()
    assert not old.exists() and new.exists() and not legacy.exists()


def test_a_cache_that_cannot_be_written_keeps_nothing_and_fails_nothing(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(blocker))
    key = diskcache.make_key(["p"])
    assert diskcache.store(key, [b"code"]) is False
    assert diskcache.load(key) is None


# -- several processes at once -----------------------------------------------------

WRITER = textwrap.dedent("""
    import sys, time
    from plcrt.compiler.native import diskcache
    key, me, rounds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    # each writer's entry: 3 objects of 1 MiB, every byte its number
    mine = [bytes([me]) * (1 << 20), bytes([me]) * 10, bytes([me]) * (1 << 19)]
    bad = seen = 0
    for i in range(rounds):
        diskcache.store(key, mine)
        got = diskcache.load(key)
        if got is not None:
            seen += 1
            sizes = [len(o) for o in got]
            whole = sizes == [1 << 20, 10, 1 << 19] and len({o[:1] for o in got}) == 1 \\
                and all(o == o[:1] * len(o) for o in got)
            bad += not whole
    print(bad, seen)
""")


def test_processes_writing_one_key_at_once_never_read_a_torn_entry(cache) -> None:
    """pytest-xdist workers load the same program at once: each renames a
    complete file over the entry, and every read is one writer's whole entry."""
    key = diskcache.make_key(["the same program"])
    env = dict(os.environ, PLCRT_CACHE_DIR=str(cache.parent))
    procs = [subprocess.Popen([sys.executable, "-c", WRITER, key, str(me), "25"],
                              stdout=subprocess.PIPE, text=True, env=env) for me in range(1, 5)]
    results = [p.communicate(timeout=120)[0].split() for p in procs]
    assert all(p.returncode == 0 for p in procs)
    assert all(r[0] == "0" for r in results), results          # no torn or mixed read
    assert all(int(r[1]) == 25 for r in results), results      # every read found an entry
    assert len(list(cache.glob("*.native"))) == 1
    assert not list(cache.glob("*.tmp"))


# -- the machine code ------------------------------------------------------------

def _mixed(networks: int) -> str:
    shapes = ("LD SM0.0\nMOVW VW{a}, VW{w}\n+I VW{b}, VW{w}\n*I +3, VW{w}",
              "LDW>= VW{a}, +{k}\nOW= VW{b}, +7\nLDD< VD{a}, VD{b}\nAB<> VB{a}, VB{b}\nOLD\n"
              "= M{m}.{bit}\nINCW VW{w}",
              "LD I0.{bit}\nAN M{m}.{bit}\nTON T{t}, +{k}\nLD T{t}\n= Q0.{bit}",
              "LD SM0.0\nMOVD VD{a}, VD{d}\n+D VD{b}, VD{d}\nMOVB VB{a}, VB{w}",
              "LD I0.0\nA I0.1\nO M{m}.{bit}\nLPS\nA M1.1\n= M{m}.{bit}\nLPP\n= Q1.{bit}")
    body = []
    for i in range(networks):
        a, b = 2 * (i % 20), 2 * (i * 7 % 20)
        body.append(shapes[i % len(shapes)].format(
            a=a, b=b, w=200 + 2 * (i % 50), d=400 + 4 * (i % 25), k=i % 300, m=i % 8,
            bit=i % 8, t=37 + i % 20))
    return "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\n" + "".join(
        f"Network {i}\n{n}\n" for i, n in enumerate(body, 1)) + "END_ORGANIZATION_BLOCK\n"


def test_a_program_in_many_modules_and_parts_runs_as_its_python_build(cache, monkeypatch):
    """Small modules and parts: a segment calls parts of other modules,
    linked in one engine, and the image equals the Python build's."""
    pytest.importorskip("llvmlite")
    import plcrt.compiler.native as native
    import plcrt.compiler.native.fn as fn
    monkeypatch.setattr(native, "MODULE_CHARS", 4000)
    monkeypatch.setattr(fn, "PART_LINES", 60)
    program_cache.clear()
    text = _mixed(60)
    py, nat = plcrt.load(text, backend="python"), plcrt.load(text, backend="native")
    assert len(nat.compiled.native_ir) >= 5 and nat.backend["segments"] == 1
    assert nat.backend["python"] == []
    v = bytes((i * 37 + 11) & 0xFF for i in range(100))
    for plc in (py, nat):
        plc.mem.areas["V"][:100] = v
    for k in range(12):
        for plc in (py, nat):
            plc.mem.areas["PI"][0] = (0, 1, 3, 2)[k % 4]
            plc.scan()
        for area in AREAS:
            assert bytes(nat.mem.areas[area]) == bytes(py.mem.areas[area]), (k, area)
    program_cache.clear()


def test_the_entry_is_keyed_by_llvmlite_and_the_cpu(cache, monkeypatch) -> None:
    pytest.importorskip("llvmlite")
    import plcrt.compiler.native.jit as jit
    text = _mixed(5)
    program_cache.clear()
    assert plcrt.load(text, backend="native").backend["cached"] is False
    program_cache.clear()
    assert plcrt.load(text, backend="native").backend["cached"] is True
    monkeypatch.setattr(jit, "llvm_version", lambda: "0.0.0-another")
    program_cache.clear()
    assert plcrt.load(text, backend="native").backend["cached"] is False
    llvm = jit._llvm()

    class Features:        # another CPU of the same name (other extensions)
        def flatten(self) -> str:
            return "+64bit,-sse2"
    monkeypatch.setattr(llvm, "get_host_cpu_features", Features)
    program_cache.clear()
    other = plcrt.load(text, backend="native")
    assert other.backend["cached"] is False
    assert len(list(cache.glob("*.native"))) == 3
    program_cache.clear()


LOADER = textwrap.dedent("""
    import sys
    import plcrt
    plc = plcrt.load(open(sys.argv[1]).read(), backend="native")
    plc.mem.areas["V"][:40] = bytes(range(40))
    plc.mem.areas["PI"][0] = 3
    plc.scan(5)
    print(plc.backend["cached"], bytes(plc.mem.areas["V"][:600]).hex(), bytes(plc.mem.areas["Q"]).hex())
""")


def test_processes_compiling_one_program_at_once_agree(cache, tmp_path) -> None:
    """Workers of one test session load one program at the same moment: all
    compile or hit, none fails, all run the same code."""
    pytest.importorskip("llvmlite")
    prog = tmp_path / "prog.awl"
    prog.write_text(_mixed(40))
    env = dict(os.environ, PLCRT_CACHE_DIR=str(cache.parent))
    procs = [subprocess.Popen([sys.executable, "-c", LOADER, str(prog)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, env=env) for _ in range(3)]
    outs = [p.communicate(timeout=300) for p in procs]
    assert all(p.returncode == 0 for p in procs), [o[1][-500:] for o in outs]
    images = {tuple(o[0].split()[1:]) for o in outs}
    assert len(images) == 1
    assert len(list(cache.glob("*.native"))) == 1
    again = subprocess.run([sys.executable, "-c", LOADER, str(prog)], capture_output=True,
                           text=True, env=env, check=True).stdout.split()
    assert again[0] == "True" and tuple(again[1:]) in images


def test_machine_code_stays_small_per_statement(cache) -> None:
    """Values loaded and stored whole, selects without branches: about 42
    bytes of machine code per statement of a mixed program (137 when
    values went byte by byte and a byte's select was a branch that put
    every live value on the stack), the same for 50 and 400 networks, so a
    large program's cost per statement stays flat."""
    pytest.importorskip("llvmlite")
    per = []
    for networks in (50, 400):
        program_cache.clear()
        plc = plcrt.load(_mixed(networks), backend="native")
        per.append(plc.compiled.native.code_bytes / plc.program.instruction_count())
    assert all(p < 64 for p in per), per
    assert max(per) / min(per) < 1.25, per
    program_cache.clear()
