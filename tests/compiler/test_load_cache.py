"""Loading: the compiled-program cache, the chunked compile of the
generated module and the paused garbage collector (plcrt.compiler.cache)."""

from __future__ import annotations

import gc
import types
from typing import Any, Iterator

import pytest

import plcrt
from plcrt.compiler import cache, codegen
from plcrt.compiler import program as compiled_program
from plcrt.engine.runtime import Plc, parse_sources

# Timers, counters, a subroutine with its own L buffer per call site, a
# table instruction (its helpers are closures over the CPU) and an edge.
PROGRAM = """\
ORGANIZATION_BLOCK OB1
BEGIN
Network 1
LD     I0.0
TON    T37, +3
Network 2
LD     T37
EU
LD     I0.1
CTU    C1, +100
Network 3
LD     SM0.0
MOVW   C1, VW10
CALL   SBR0, VW10, VW20
Network 4
LD     SM0.1
MOVW   +4, VW100
MOVW   +0, VW102
Network 5
LD     T37
EU
ATT    VW20, VW100
END_ORGANIZATION_BLOCK
SUBROUTINE_BLOCK SBR0
VAR_INPUT
X:INT;
END_VAR
VAR_OUTPUT
Y:INT;
END_VAR
BEGIN
Network 1
LD     SM0.0
MOVW   #X, #Y
+I     +7, #Y
END_SUBROUTINE_BLOCK
"""


@pytest.fixture
def fresh_cache() -> Iterator[cache.ProgramCache]:
    """An empty process cache for the test, emptied again after it."""
    cache.programs.clear()
    yield cache.programs
    cache.programs.clear()
    cache.programs.max_entries = cache.DEFAULT_ENTRIES


def _drive(plc: Plc, scans: int = 200) -> bytes:
    """Run a fixed input pattern (T37 elapses every 60 scans); the memory
    image afterwards."""
    for i in range(scans):
        plc["I0.0"] = 1 if i % 60 < 45 else 0
        plc.scan()
    return b"".join(bytes(buf) for buf in plc.mem.areas.values())


def test_a_cached_program_runs_like_a_fresh_compile(fresh_cache: cache.ProgramCache) -> None:
    first = plcrt.load(PROGRAM)
    second = plcrt.load(PROGRAM)              # parsed again: equal text, a cache hit
    assert (fresh_cache.misses, fresh_cache.hits) == (1, 1)
    assert second.unit is first.unit and second._entry is first._entry   # one compile, shared
    fresh_cache.max_entries = 0               # caching off: every load compiles
    uncached = plcrt.load(PROGRAM)
    assert uncached.unit is not first.unit
    reference = _drive(uncached)
    assert _drive(second) == reference and _drive(first) == reference
    assert first["VW20"] == first["C1"] + 7 and first["VW102"] > 0   # CALL and ATT ran


def _reachable(roots: list[Any], plc: Plc) -> Iterator[Any]:
    """Objects a PLC's run-time bindings lead to: closure cells, default
    arguments, bound objects, container items, attributes (not modules,
    classes or functions' globals, and not past the PLC itself)."""
    seen: set[int] = {id(plc)}
    todo = list(roots)
    while todo:
        obj = todo.pop()
        if id(obj) in seen or isinstance(obj, (type, types.ModuleType, str, bytes, int, float)):
            continue
        seen.add(id(obj))
        yield obj
        if isinstance(obj, types.FunctionType):
            todo += [c.cell_contents for c in obj.__closure__ or () if c != types.CellType()]
            todo += list(obj.__defaults__ or ())
        elif isinstance(obj, types.MethodType):
            todo.append(obj.__self__)
        elif isinstance(obj, (list, tuple, set, frozenset)):
            todo += list(obj)
        elif isinstance(obj, dict):
            todo += list(obj.values())
        elif hasattr(obj, "__dict__"):
            todo += list(vars(obj).values())


def test_plcs_of_one_cached_program_share_no_state(fresh_cache: cache.ProgramCache) -> None:
    program = parse_sources(PROGRAM)
    one, two = Plc(program), Plc(program)
    assert two._entry is one._entry
    functions = [v for k, v in two._ns.items() if k.startswith(("pou_", "n_"))]
    for obj in _reachable(functions + list(two._bindings.values()), two):
        assert obj is not one, "a binding leads to another PLC"
    _drive(one)
    assert bytes(two.mem.areas["V"]) == bytes(len(two.mem.areas["V"])) and two.scans == 0
    # the table helpers (closures over the CPU) work on this PLC: same run, same result
    assert _drive(two) == _drive(Plc(program))


def test_options_that_change_the_code_are_part_of_the_key(
        fresh_cache: cache.ProgramCache) -> None:
    program = parse_sources(PROGRAM)
    Plc(program)
    Plc(program, cpu="CPU224")
    Plc(program, instrument=True)
    Plc(program, scan_ms=5)                   # the scan time changes no code
    assert (fresh_cache.misses, fresh_cache.hits) == (3, 1)
    with_probes = Plc(program, instrument=True)
    assert fresh_cache.hits == 2 and with_probes.coverage is not None
    with_probes["I0.0"] = 1
    with_probes.scan()
    # the probes' tables are the PLC's own
    assert Plc(program, instrument=True).coverage.hits != with_probes.coverage.hits


def test_merged_programs_with_the_same_first_file_are_told_apart(
        fresh_cache: cache.ProgramCache) -> None:
    sbr = "SUBROUTINE_BLOCK SBR0\nBEGIN\nNetwork 1\nLD     SM0.0\nMOVW   +{}, VW0\n" \
          "END_SUBROUTINE_BLOCK\n"
    main = "ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD     SM0.0\nCALL   SBR0\n" \
           "END_ORGANIZATION_BLOCK\n"
    a = plcrt.load([main, sbr.format(1)])
    b = plcrt.load([main, sbr.format(2)])
    a.scan()
    b.scan()
    assert (a["VW0"], b["VW0"]) == (1, 2)
    assert fresh_cache.hits == 0


def test_the_least_recently_used_program_goes_first(fresh_cache: cache.ProgramCache) -> None:
    fresh_cache.max_entries = 2
    texts = [PROGRAM.replace("+3", f"+{n}") for n in (3, 4, 5)]
    for t in texts:
        plcrt.load(t)
    assert len(fresh_cache) == 2
    plcrt.load(texts[2])
    plcrt.load(texts[0])                      # evicted: compiled again
    assert (fresh_cache.hits, fresh_cache.misses) == (1, 4)


def test_a_fork_never_compiles_again(fresh_cache: cache.ProgramCache) -> None:
    plc = plcrt.load(PROGRAM)
    fresh_cache.clear()
    twin = plc.fork()
    assert fresh_cache.misses == 0 and twin.unit is plc.unit
    assert _drive(twin) == _drive(plc.fork())


def test_chunks_keep_the_line_numbers_of_the_whole_module(
        monkeypatch: pytest.MonkeyPatch, fresh_cache: cache.ProgramCache) -> None:
    monkeypatch.setattr(cache, "CHUNK_LINES", 20)
    monkeypatch.setattr(codegen, "GROUP_PIECES", 1)     # a function per network
    nets = "".join(f"Network {n}\nLD     SM0.0\nMOVW   +{n}, VW{2 * n}\nLD     I0.{n % 8}\n"
                   f"A      M0.{n % 7}\n=      Q{n % 4}.{n % 8}\n" for n in range(1, 60))
    text = f"ORGANIZATION_BLOCK OB1\nBEGIN\n{nets}END_ORGANIZATION_BLOCK\n"
    plc = plcrt.load(text)
    assert len(plc.unit.chunks) > 5 and len(plc._entry.codes) == len(plc.unit.chunks)
    lines = plc.source.splitlines()
    defs = [(k, f) for k, f in plc._ns.items() if isinstance(f, types.FunctionType)
            and f.__code__.co_filename == plc._filename]
    assert sorted(k for k, _ in defs) == sorted([f"n_OB1_{n}_{n - 1}" for n in range(1, 60)]
                                                + ["pou_OB1"])
    for name, fn in defs:
        assert lines[fn.__code__.co_firstlineno - 1].startswith(f"def {name}(")
        # every line the function runs is inside its own definition
        body = {ln for _, _, ln in fn.__code__.co_lines() if ln is not None}
        assert all(lines[ln - 1].startswith("    ") for ln in body - {fn.__code__.co_firstlineno})
    plc.scan()
    assert plc["VW118"] == 59 and plcrt.load(text.replace("+59", "+58")).unit.chunks


def test_a_fault_in_a_late_chunk_is_located_at_its_instruction(
        monkeypatch: pytest.MonkeyPatch, fresh_cache: cache.ProgramCache) -> None:
    monkeypatch.setattr(cache, "CHUNK_LINES", 10)
    monkeypatch.setattr(codegen, "GROUP_PIECES", 4)     # networks 1-4, 5-8, ...
    nets = "".join(f"Network {n}\nLD     SM0.0\nMOVW   +{n}, VW{2 * n}\n" for n in range(1, 40))
    text = f"ORGANIZATION_BLOCK OB1\nBEGIN\n{nets}END_ORGANIZATION_BLOCK\n"
    plc = plcrt.load(text, backend="python")    # the Python backend's functions
    assert len(plc.unit.chunks) > 3
    # the function of networks 33-36 with its memory buffers taken away
    # fails at network 33's MOVW: the traceback's generated line leads to
    # that STL line
    fn = plc._ns["g_OB1_8_32"]
    broken = types.FunctionType(fn.__code__, fn.__globals__, fn.__name__,
                                tuple(None for _ in fn.__defaults__ or ()))
    with pytest.raises(TypeError) as err:
        broken(bytearray(64))
    loc = plc._loc_from_tb(err.value)
    assert loc is not None and loc.line == text.splitlines().index("MOVW   +33, VW66") + 1


def _sixty_networks() -> str:
    nets = "".join(f"Network {n}\nLD     SM0.0\nMOVW   +{n}, VW{2 * n}\n" for n in range(1, 60))
    return f"ORGANIZATION_BLOCK OB1\nBEGIN\n{nets}END_ORGANIZATION_BLOCK\n"


def test_chunks_start_at_top_level_statements_where_the_text_says(
        monkeypatch: pytest.MonkeyPatch, fresh_cache: cache.ProgramCache) -> None:
    """The generator keeps a finished chunk as one text: each chunk's first
    line and character offset agree with the whole module's text."""
    monkeypatch.setattr(cache, "CHUNK_LINES", 20)
    monkeypatch.setattr(codegen, "GROUP_PIECES", 2)
    plc = plcrt.load(_sixty_networks())
    source, chunks = plc.source, plc.unit.chunks
    assert len(chunks) > 5 and chunks[0] == (1, 0)
    for line, offset in chunks[1:]:
        assert source[offset - 1] == "\n" and source[offset:offset + 4] == "def "
        assert source.count("\n", 0, offset) == line - 1
    plc.scan()
    assert plc["VW118"] == 59


def test_generated_code_that_does_not_compile_is_an_internal_error(
        monkeypatch: pytest.MonkeyPatch, fresh_cache: cache.ProgramCache) -> None:
    monkeypatch.setattr(codegen, "_runner", lambda *a: ["def pou_OB1(L) oops"])
    with pytest.raises(plcrt.PlcConfigError, match="internal error: generated code does "
                                                   "not compile"):
        plcrt.load(PROGRAM)


def test_the_collector_is_off_while_compiling_and_restored_after(
        monkeypatch: pytest.MonkeyPatch, fresh_cache: cache.ProgramCache) -> None:
    seen: list[bool] = []
    original = compiled_program.compile_program

    def spy(*args: Any, **kw: Any) -> Any:
        seen.append(gc.isenabled())
        return original(*args, **kw)

    monkeypatch.setattr(compiled_program, "compile_program", spy)
    assert gc.isenabled()
    plcrt.load(PROGRAM)
    assert seen == [False] and gc.isenabled()
    with pytest.raises(plcrt.PlcCompileError):
        plcrt.load(PROGRAM.replace("TON    T37", "FOO    T37"))
    assert gc.isenabled()                     # restored after an error too
    gc.disable()
    try:
        plcrt.load(PROGRAM + "\n")
        assert not gc.isenabled()             # a caller's choice stays
    finally:
        gc.enable()


def test_nested_pauses_restore_once() -> None:
    assert gc.isenabled()
    with cache.gc_paused():
        with cache.gc_paused():
            pass
        assert not gc.isenabled()
    assert gc.isenabled()
