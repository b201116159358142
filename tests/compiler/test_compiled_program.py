"""The compiled program (plcrt.compiler.program): one immutable value per
program and options, holding no engine object, shared by every PLC of it
through the cache, picklable, and instanced in another process."""

from __future__ import annotations

import gc
import multiprocessing
import pickle
import types
from pathlib import Path
from typing import Any, Iterator

import pytest

import plcrt
from plcrt.blocks.library import LibraryBlock
from plcrt.compiler import cache
from plcrt.compiler.native.jit import available as native_available
from plcrt.compiler.program import CompiledProgram
from plcrt.engine.runtime import Plc
from plcrt.memory import MemoryImage

ROOT = Path(__file__).resolve().parents[2]
EM253 = ROOT / "programs" / "em253"
BACKENDS = ["python"] + (["native"] if native_available() else [])

# Timers, counters, an edge, a subroutine with its own L buffer, a table
# instruction (helpers made for each CPU), the 1 ms timer, real math (a
# helper made for each PLC) and a STOP: a binding of every kind of recipe.
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
BITIM  VD40
Network 4
LD     SM0.1
MOVW   +4, VW100
MOVW   +0, VW102
MOVR   2.0, VD50
Network 5
LD     T37
EU
ATT    VW20, VW100
SQRT   VD50, VD54
Network 6
LD     I0.2
STOP
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
    cache.programs.clear()
    yield cache.programs
    cache.programs.clear()
    cache.programs.max_entries = cache.DEFAULT_ENTRIES


def image_after(plc: Plc, scans: int = 150) -> bytes:
    """The memory image after a fixed stimulus (I0.0 toggled every 40
    scans, I0.1 every 7; T37 elapses while I0.0 is on)."""
    for i in range(scans):
        plc["I0.0"] = 1 if i % 80 < 40 else 0
        plc["I0.1"] = (i // 7) % 2
        plc.scan()
    return b"".join(bytes(buf) for buf in plc.mem.areas.values())


def _em253() -> Plc:
    return plcrt.load(EM253 / "pos_run.awl", plant=EM253 / "plant.toml",
                      data=EM253 / "pos_run.db")


def _em253_image(plc: Plc, scans: int = 300) -> tuple[bytes, list[Any]]:
    """Run the EM253 example (M3.0 starts the envelope at scan 10) and
    return the memory image and the axes' state."""
    for i in range(scans):
        plc["M3.0"] = 1 if i >= 10 else 0
        plc.scan()
    image = b"".join(bytes(buf) for buf in plc.mem.areas.values())
    return image, [a.to_dict() for a in plc.axes()]


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_pickled_program_runs_like_the_original(backend: str,
                                                  fresh_cache: cache.ProgramCache) -> None:
    plc = plcrt.load(PROGRAM, backend=backend)
    compiled = plc.compiled
    copy_ = pickle.loads(pickle.dumps(compiled))
    assert isinstance(copy_, CompiledProgram) and copy_ is not compiled
    reference = image_after(plc)
    again = Plc.from_program(copy_)
    assert again.compiled is copy_ and again.backend["name"] == backend
    assert image_after(again) == reference
    assert again["VW20"] == again["C1"] + 7 and again["VW102"] > 0   # CALL and ATT ran
    assert again["VD54"] == plc["VD54"] != 0 and again["VD40"] == plc["VD40"] != 0


def test_a_pickled_program_with_library_blocks_and_a_plant_runs_alike(
        fresh_cache: cache.ProgramCache) -> None:
    plc = _em253()
    copy_ = pickle.loads(pickle.dumps(plc.compiled))
    twin = Plc.from_program(copy_)
    # load() applied the data block: the twin starts from the same V memory
    twin.mem.areas["V"][:] = plc.mem.areas["V"]
    first, axes = _em253_image(plc)
    assert _em253_image(twin) == (first, axes)
    assert any(a["position"] != 0 for a in axes), "the envelope ran"


def _child(blob: bytes, scans: int) -> bytes:
    """In a spawned interpreter: a PLC of the unpickled program, run."""
    compiled = pickle.loads(blob)
    return image_after(Plc.from_program(compiled), scans)


def test_a_program_compiled_here_runs_identically_in_another_process(
        fresh_cache: cache.ProgramCache) -> None:
    plc = plcrt.load(PROGRAM)
    blob = pickle.dumps(plc.compiled)
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(1) as pool:
        image = pool.apply(_child, (blob, 150))
    assert image == image_after(plc, 150)


def test_plcs_of_one_compiled_program_share_neither_memory_nor_devices(
        fresh_cache: cache.ProgramCache) -> None:
    a = _em253()
    power_up = b"".join(bytes(buf) for buf in a.mem.areas.values())
    b = Plc.from_program(a.compiled)
    b.mem.areas["V"][:] = a.mem.areas["V"]     # the data block load() applied
    c = _em253()                              # parsed again: a cache hit
    assert b.compiled is a.compiled and c.compiled is a.compiled
    assert fresh_cache.misses == 1
    for x, y in ((a, b), (a, c), (b, c)):
        assert x.mem is not y.mem and x.timers is not y.timers
        assert all(k is not m for k, m in zip(x.mem.areas.values(), y.mem.areas.values()))
        assert len(x.devices) == len(y.devices) > 0
        assert all(d is not e for d, e in zip(x.devices, y.devices))
        state_x = [o for n, o in x._bindings.items() if not _shared(n, o, x)]
        state_y = {id(o) for n, o in y._bindings.items() if not _shared(n, o, y)}
        assert state_x and not any(id(o) in state_y for o in state_x)
        blocks = [o for o in x._bindings.values() if hasattr(o, "plc")]
        assert blocks and all(o.plc is x for o in blocks)
    image, axes = _em253_image(a)
    assert any(ax["position"] != 0 for ax in axes), "the envelope ran"
    # running one PLC left the others at power-up
    for other in (b, c):
        assert other.scans == 0 and all(ax["position"] == 0 for ax in other.axes())
        assert b"".join(bytes(buf) for buf in other.mem.areas.values()) == power_up


def _shared(name: str, obj: Any, plc: Plc) -> bool:
    """A binding every PLC of the program shares: a constant, a plain function."""
    return name in plc.unit.constants or isinstance(obj, (types.FunctionType,
                                                           types.BuiltinFunctionType, type))


def _engine_object(obj: Any) -> bool:
    """A run-time object of a PLC: the PLC, anything of the engine (its
    memory image, timer bank, interrupts, ports ...; the probe tables of
    plcrt.engine.coverage are plain data a program owns), a device (what
    the scan steps), a library block or anything else that holds a PLC."""
    module = type(obj).__module__
    return (isinstance(obj, (Plc, MemoryImage, LibraryBlock))
            or module.startswith("plcrt.devices.") and callable(getattr(obj, "step", None))
            or module.startswith("plcrt.engine.") and module != "plcrt.engine.coverage"
            or isinstance(getattr(obj, "__dict__", None), dict) and "plc" in vars(obj))


def _reachable(root: Any) -> Iterator[Any]:
    """Everything ``root`` leads to: attributes, items, slots, closure cells
    and defaults, bound objects (not classes, modules, code, or a
    function's globals)."""
    seen: set[int] = set()
    todo = [root]
    while todo:
        obj = todo.pop()
        if id(obj) in seen or isinstance(obj, (type, types.ModuleType, types.CodeType)):
            continue
        seen.add(id(obj))
        yield obj
        if isinstance(obj, types.FunctionType):
            todo += [c.cell_contents for c in obj.__closure__ or ()
                     if c != types.CellType()]
            todo += list(obj.__defaults__ or ())
        else:
            todo += gc.get_referents(obj)


@pytest.mark.parametrize("options", [{}, {"instrument": True}, {"backend": "native"}],
                         ids=["plain", "instrumented", "native"])
def test_a_compiled_program_holds_no_engine_object(options: dict[str, Any],
                                                   fresh_cache: cache.ProgramCache) -> None:
    if options.get("backend") == "native" and not native_available():
        pytest.skip("llvmlite is not installed")
    plcs = [plcrt.load(PROGRAM, **options), _em253()]
    for plc in plcs:
        found = [o for o in _reachable(plc.compiled) if _engine_object(o)]
        assert not found, f"engine objects in the compiled program: {found[:3]}"
        assert not any(o is plc for o in _reachable(plc.compiled))


@pytest.mark.parametrize("program", ["modbus/poll.awl", "uss/drive.awl", "events/pto_wizard.awl"])
def test_a_plc_with_library_blocks_is_freed_with_its_last_reference(
        program: str, fresh_cache: cache.ProgramCache) -> None:
    """A library family's state per CPU lives in the PLC
    (``family_states``), so nothing outside keeps a dropped PLC alive; the
    compiled program, kept by the cache, holds none of its objects."""
    import weakref
    path = ROOT / "programs" / program
    plant = next(iter(sorted(path.parent.glob(f"{path.stem}*.toml"))
                      or sorted(path.parent.glob("*plant.toml"))), None)
    plc = plcrt.load(path, plant=plant)
    assert plc.family_states, "the program keeps a family's state"
    plc.scan()
    gone = weakref.ref(plc)
    del plc
    gc.collect()
    assert gone() is None and len(fresh_cache) == 1


class _Broken:
    """A library block whose factory fails (a plcrt bug)."""

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        raise RuntimeError("broken factory")

    def __call__(self, *args: int) -> tuple:
        return ()


def test_a_block_that_cannot_be_made_for_a_plc_is_an_internal_error(
        monkeypatch: pytest.MonkeyPatch, fresh_cache: cache.ProgramCache) -> None:
    """The compiler never makes a block (each PLC does, from its recipe):
    a factory that fails is reported as plcrt's error, not a traceback."""
    from plcrt.blocks import BLOCK_FACTORIES, load_libraries
    load_libraries()
    monkeypatch.setitem(BLOCK_FACTORIES, "GET_ABSPOS", _Broken)
    text = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD     SM0.0\n"
            "CALL   GET_AbsPos, 0, 0, VD0, VW4\nEND_ORGANIZATION_BLOCK\n")
    with pytest.raises(plcrt.PlcConfigError, match="internal error.*broken factory"):
        plcrt.load(text)
