"""Forcing, observers, fork/snapshot/restore and coverage probes of the engine."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import plcrt
from plcrt.errors import PlcAddressError, PlcConfigError
from stl_helpers import ob1_text

ROOT = Path(__file__).resolve().parents[2]

COUNTING = ob1_text(
    "LD SM0.0\nINCW VW0",              # VW0 counts scans
    "LD SM0.0\nMOVW VW0, VW2",         # the program writes VW2 every scan
    "LD I0.0\n= Q0.0",
    "LD I0.1\nTON T37, +5",            # a 100 ms timer: state outside memory
    "LD I0.2\nEU\nINCW VW4",           # edge memory
    "LD I0.3\nLD I0.4\nCTU C1, +3",    # counter input state (CTU: count, reset)
)


def test_force_overrides_program_writes_at_scan_end() -> None:
    """A forced word keeps its value at the end of every scan although the
    program writes it (System Manual: force values are applied when inputs
    are read and before outputs are written)."""
    plc = plcrt.load(COUNTING)
    plc.force("VW2", 1234)
    plc.scan(3)
    assert plc["VW0"] == 3
    assert plc["VW2"] == 1234
    plc.unforce("VW2")
    plc.scan(1)
    assert plc["VW2"] == 4


def test_force_input_wins_over_physical_input_and_reaches_output() -> None:
    plc = plcrt.load(COUNTING)
    plc.force("I0.0", 1)
    plc.write("I0.0", 0)          # the terminal says 0, the force says 1
    plc.scan(1)
    assert plc["Q0.0"] == 1
    assert plc.mem.areas["PQ"][0] & 1 == 1
    plc.force("Q0.0", 0)          # forcing the output beats the program
    plc.scan(1)
    assert plc.mem.areas["PQ"][0] & 1 == 0
    assert plc.forces == {"I0.0": 1, "Q0.0": 0}
    plc.unforce()
    assert plc.forces == {}


def test_force_errors_are_clear() -> None:
    plc = plcrt.load(COUNTING)
    with pytest.raises(PlcAddressError, match="does not fit"):
        plc.force("VB0", 300)
    with pytest.raises(PlcAddressError, match="not forced"):
        plc.unforce("VW8")


def test_observers_run_after_every_scan() -> None:
    plc = plcrt.load(COUNTING)
    seen: list[tuple[int, int]] = []
    plc.observers.append(lambda p: seen.append((p.scans, p["VW0"])))
    plc.scan(3)
    assert seen == [(1, 1), (2, 2), (3, 3)]


def _state(plc: plcrt.Plc) -> tuple:
    return (plc.scans, plc.now_us, bytes(plc.mem.areas["V"][:16]), plc["T37"],
            plc.read("T37", "BIT"), plc["C1"], plc["Q0.0"])


def test_fork_is_equal_and_independent() -> None:
    """A fork continues exactly like the original, and neither sees the
    other's writes afterwards."""
    a = plcrt.load(COUNTING)
    a.write("I0.1", 1)
    a.write("I0.3", 1)
    a.scan(7)
    b = a.fork()
    assert _state(a) == _state(b)
    for p in (a, b):
        p.write("I0.3", 0)
        p.scan(40)
    assert _state(a) == _state(b)
    b.write("I0.1", 0)
    b.scan(1)
    assert a["T37"] > 0 and b["T37"] == 0


def test_snapshot_restore_goes_back_in_time() -> None:
    plc = plcrt.load(COUNTING)
    plc.write("I0.1", 1)
    plc.scan(5)
    snap = plc.snapshot()
    before = _state(plc)
    plc.scan(30)
    assert _state(plc) != before
    plc.restore(snap)
    assert _state(plc) == before
    other = plcrt.load(COUNTING)
    with pytest.raises(PlcConfigError, match="different program"):
        other.restore(snap)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 4), st.booleans()), min_size=1, max_size=30),
       st.integers(0, 29))
def test_fork_anywhere_replays_identically(steps: list[tuple[int, bool]], cut: int) -> None:
    """Property: forking at any scan and applying the same inputs gives the
    same memory as the original, scan by scan."""
    a = plcrt.load(COUNTING)
    b = None
    for i, (bit, value) in enumerate(steps):
        if i == cut:
            b = a.fork()
        for p in (a, b) if b is not None else (a,):
            p.write(f"I0.{bit}", value)
            p.scan(1)
        if b is not None:
            assert _state(a) == _state(b)


def test_fork_in_the_middle_of_a_homing_move() -> None:
    """Device and library-block state (an EM253 homing in progress) forks
    too: both twins end at the home position the manual's example gives."""
    prog = ROOT / "programs" / "em253" / "homing.awl"
    plant = ROOT / "programs" / "em253" / "homing_plant.toml"
    a = plcrt.load(prog, plant=plant, scan_ms=1)
    a.write("M4.0", 1)
    a.write("M4.2", 1)
    a.run(seconds=1.0)
    assert any(ax["status"] == "moving" for ax in a.axes())
    b = a.fork()
    a.run(seconds=9.0)
    b.run(seconds=9.0)
    assert a.axes() == b.axes()
    assert [ax["mechanical"] for ax in b.axes()] == [21000, 20001]
    assert b["VW406"] == a["VW406"] == 8


def test_coverage_probes_record_networks_and_power_flow() -> None:
    """With instrument=True: networks skipped by a JMP are not marked, and
    each coil records whether it was reached with and without power."""
    text = ob1_text(
        "LD I0.0\n= Q0.0",
        "LD I0.1\nJMP 1",
        "LD SM0.0\n= Q0.1",
        "LBL 1",
    )
    plc = plcrt.load(text, instrument=True)
    cov = plc.coverage
    assert cov is not None
    assert [n.name for n in cov.networks] == ["OB1/1", "OB1/2", "OB1/3", "OB1/4"]
    plc.write("I0.1", 1)
    plc.scan(1)
    data = cov.data()
    assert data["networks"] == {"OB1/1": 1, "OB1/2": 1, "OB1/3": 0, "OB1/4": 1}
    q00 = next(k for k in data["outputs"] if k.startswith("OB1/1:"))
    assert data["outputs"][q00] == 1          # reached, never powered
    plc.write("I0.0", 1)
    plc.write("I0.1", 0)
    plc.scan(1)
    data = cov.data()
    assert data["outputs"][q00] == 3          # both outcomes seen
    assert data["networks"]["OB1/3"] == 1
    contacts = data["contacts"]
    i00 = next(k for k in contacts if k.startswith("OB1/1:"))
    assert contacts[i00] == 3                 # I0.0 seen open, then closed
    # SM0.0 is always closed and its coil always powered: neither is a goal
    assert not [k for k in (*contacts, *data["outputs"]) if k.startswith("OB1/3:")]
    cov.reset()
    assert set(cov.data()["networks"].values()) == {0}
    assert set(cov.data()["contacts"].values()) == {0}


def test_contact_probes_keep_a_full_stack_intact() -> None:
    """With nine levels in use a contact is not split into LD + OLD (that
    would push a tenth level and lose the bottom one); it runs unprobed."""
    loads = "\n".join(f"LD I0.{i}" for i in range(8)) + "\nLD I1.0"
    text = ob1_text(loads + "\nO I1.1\n" + "\n".join(["ALD"] * 8) + "\n= Q0.0")
    plain, probed = plcrt.load(text), plcrt.load(text, instrument=True)
    for p in (plain, probed):
        p.write("IB0", 255)
        p.write("I1.1", 1)
        p.scan(1)
    assert plain["Q0.0"] == probed["Q0.0"] == 1
    names = [c.mnemonic for c in probed.coverage.contacts]
    assert names.count("LD") == 9 and "O" not in names


def test_breakpoint_handler_runs_inside_the_scan() -> None:
    """A breakpoint calls the handler before the network executes: outputs
    of earlier networks of this scan are visible, later ones are not yet."""
    text = ob1_text("LD I0.0\n= Q0.0", "LD Q0.0\n= Q0.1")
    plc = plcrt.load(text, instrument=True)
    cov = plc.coverage
    seen = []
    cov.on_break = lambda net: seen.append((net.name, plc["Q0.0"], plc["Q0.1"]))
    cov.breakpoints[cov.find("OB1", 2).index] = 1
    plc.write("I0.0", 1)
    plc.scan(2)
    assert seen == [("OB1/2", 1, 0), ("OB1/2", 1, 1)]


def test_uninstrumented_code_has_no_probes() -> None:
    plc = plcrt.load(COUNTING)
    assert plc.coverage is None
    assert "_NC" not in plc.source and "_OC" not in plc.source


# ---------------------------------------------------------------------------
# A force belongs to its memory location, not to the name it was made with
# ---------------------------------------------------------------------------

SYMBOLS = "Start\tI0.0\tstart button\nLamp\tQ0.0\tlamp\n"


def test_force_by_symbol_unforce_by_address_and_the_reverse() -> None:
    plc = plcrt.load(COUNTING, symbols=SYMBOLS)
    plc.force("Start", 1)
    assert plc.unforce(" i0.0 ") == "Start"          # any spelling of the location
    assert plc.forces == {} and plc._force_slots == []
    plc.force("I0.0", 1)
    assert plc.unforce("Start") == "I0.0"
    assert plc.forces == {}
    with pytest.raises(PlcAddressError, match="Start is not forced"):
        plc.unforce("Start")


def test_forcing_a_location_again_replaces_its_force_under_the_new_name() -> None:
    plc = plcrt.load(COUNTING, symbols=SYMBOLS)
    plc.force("Start", 1)
    plc.force("I0.0", 0)
    assert plc.forces == {"I0.0": 0}                  # one force, not two that disagree
    plc.scan(1)
    assert plc["I0.0"] == 0
    plc.unforce("Start")
    assert plc.forces == {}


def test_forces_of_equal_looking_images_stay_apart() -> None:
    """I0.0 and Q0.0 have the same offset in two images that are equal while
    both are all zeros; forcing one must not drop the other (bytearrays
    compare by content)."""
    plc = plcrt.load(COUNTING)
    plc.force("I0.0", 0)
    plc.force("Q0.0", 0)
    assert plc.forces == {"I0.0": 0, "Q0.0": 0}
    assert len(plc._force_slots) == 2
    plc.mem.areas["PI"][0] = 1          # the terminal says 1, the force says 0
    plc.scan(1)
    assert plc["I0.0"] == 0
    plc.unforce("Q0.0")
    assert plc.forces == {"I0.0": 0}
    plc.scan(1)
    assert plc["I0.0"] == 0


def test_fork_keeps_one_force_per_location() -> None:
    plc = plcrt.load(COUNTING, symbols=SYMBOLS)
    plc.force("Lamp", 1)
    plc.force("VW2", 7)
    twin = plc.fork()
    assert twin.forces == {"Lamp": 1, "VW2": 7}
    assert twin.unforce("Q0.0") == "Lamp" and twin.forces == {"VW2": 7}
    assert plc.forces == {"Lamp": 1, "VW2": 7}


# ---------------------------------------------------------------------------
# Values the memory cannot hold are errors, never silently changed
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("address, value, message", [
    ("I0.0", 5, "I0.0: a bit takes 0 or 1, got 5"),
    ("Q0.0", -1, "Q0.0: a bit takes 0 or 1, got -1"),
    ("VD0", 1e39, "VD0: 1e+39 is out of the range of a REAL"),
    ("VD0", -1e39, "VD0: -1e+39 is out of the range of a REAL"),
    ("VW0", "12", "VW0: '12' is not a number"),
    ("I0.0", None, "I0.0: None is not a number"),
])
def test_write_and_force_refuse_values_that_do_not_fit(address: str, value: object,
                                                       message: str) -> None:
    plc = plcrt.load(COUNTING)
    for action in (plc.write, plc.force):
        with pytest.raises(PlcAddressError, match=message.replace("+", r"\+")):
            action(address, value)  # type: ignore[operator]
    assert plc.forces == {}
    assert plc["VD0"] == 0


def test_write_accepts_bools_numpy_numbers_and_infinite_reals() -> None:
    np = pytest.importorskip("numpy")
    plc = plcrt.load(COUNTING)
    plc.write("I0.0", True)
    plc.write("Q0.0", np.int64(1))
    plc.write("VW2", np.int16(-5))
    plc.write("VD4", float("inf"))
    plc.write("VD8", np.float32(1.5))
    assert (plc["I0.0"], plc["Q0.0"], plc["VW2"]) == (1, 1, -5)
    assert plc.read("VD4", "REAL") == float("inf") and plc.read("VD8", "REAL") == 1.5


# ---------------------------------------------------------------------------
# restore
# ---------------------------------------------------------------------------

def test_restore_of_a_fork_snapshot_and_of_things_that_are_not_snapshots() -> None:
    plc = plcrt.load(COUNTING)
    plc.write("I0.1", 1)
    twin = plc.fork()
    twin.scan(7)
    plc.restore(twin.snapshot())        # a fork shares the program: allowed
    assert plc.scans == 7 and plc["VW0"] == 7
    with pytest.raises(PlcConfigError, match="needs a snapshot made by snapshot"):
        plc.restore(42)  # type: ignore[arg-type]


@pytest.mark.parametrize("options", [{"cpu": "CPU222"}, {"instrument": True}])
def test_restore_refuses_the_same_program_compiled_differently(options: dict) -> None:
    """The pytest plugin parses a file once and compiles it per test, so two
    PLCs can share the program object yet differ; restoring across them
    resized V memory (CPU222 has less) or failed with an internal error."""
    from plcrt.engine.runtime import Plc, parse_sources

    program = parse_sources(COUNTING)
    plc, other = Plc(program), Plc(program, **options)
    other.scan(3)
    v_size = len(plc.mem.areas["V"])
    with pytest.raises(PlcConfigError, match="compiled with other options"):
        plc.restore(other.snapshot())
    assert len(plc.mem.areas["V"]) == v_size and plc.scans == 0
