"""The STL library for CiA 402 drives (library/cia402/drive_lib.awl), block
by block, on both drive models: what each block writes into the drive's
image, when its outputs change, and where each drive ends up (exact counts
and statuswords from ``plc.drive(1)`` and from V memory).

The rig (drive_rig.awl) calls every block once per scan for drive 1, whose
image is VB1000..VB1079, with the inputs on I0.x and the outputs in M and V.
It fills AC0..AC3 before the calls and copies them after, to check that the
library leaves the accumulators alone.
"""

from __future__ import annotations

from pathlib import Path

import pytest

LIB = Path(__file__).resolve().parents[2] / "library" / "cia402" / "drive_lib.awl"

RIG = str(Path(__file__).with_name("drive_rig.awl"))

PLANT = {
    "hcfa-am0520b": {},
    "kinco-servo": {"6099:05": 1},           # the count reads -607Ch at home (Kinco §2.3-3)
}
MODELS = list(PLANT)
#: the statusword of PP at rest on the target, not homed: HCFA bit 15
#: "can trigger" (§7.5.3); Kinco bit 15 is "reference found" (Kinco §2.6)
PP_IDLE = {"hcfa-am0520b": 0x8637, "kinco-servo": 0x0637}
HOMED = {"hcfa-am0520b": 0x1637, "kinco-servo": 0x9637}
#: the count at the home point for 607Ch = +250
OFFSET_250 = {"hcfa-am0520b": 250, "kinco-servo": -250}


def u16(x: int) -> int:
    return x & 0xFFFF


class Rig:
    """One drive under the rig program; methods press the rig's inputs."""

    def __init__(self, h, model: str) -> None:
        self.h = h
        self.model = model
        h["VD44"], h["VD48"], h["VD52"] = 40000, 200000, 200000

    @property
    def drive(self):
        return self.h.plc.drive(1)

    @property
    def sim(self):
        return self.h.plc.module(0).drive(1)

    def image(self, name: str) -> int:
        offset, kind = {"cw": (0, "VW"), "mode": (2, "VB"), "method": (3, "VB"),
                        "target": (4, "VD"), "velocity": (8, "VD"), "sw": (32, "VW"),
                        "status": (35, "VB"), "position": (36, "VD")}[name]
        value = self.h[f"{kind}{1000 + offset}"]
        return u16(value) if kind == "VW" else value

    def enable(self) -> None:
        self.h["I0.0"] = 1
        self.h.run_until("M0.0", timeout=2)

    def run_block(self, execute: str, done: str, error: str, timeout: float = 30) -> str:
        """Raise *execute*, wait for done or error, drop it; which came."""
        h = self.h
        h[execute] = 1
        h.run_until(lambda: h[done] or h[error], timeout=timeout)
        came = done if h[done] else error
        h[execute] = 0
        h.scan()
        return came

    def home(self, method: int) -> str:
        self.h["VW12"] = method
        return self.run_block("I0.1", "M1.1", "M1.2")

    def move(self, position: int, relative: bool = False) -> str:
        self.h["VD40"] = position
        self.h["I0.3"] = int(relative)
        return self.run_block("I0.2", "M2.1", "M2.2")

    def write(self, index: int, sub: int, value: int) -> str:
        self.h["VW70"], self.h["VB72"], self.h["VD64"] = index, sub, value
        return self.run_block("I0.6", "M5.1", "M5.2")

    def read(self, index: int, sub: int) -> str:
        self.h["VW60"], self.h["VB62"] = index, sub
        return self.run_block("I0.5", "M4.1", "M4.2")


def make_rig(plc_factory, model: str, scan_ms: float = 10, cycle_ms: float = 1) -> Rig:
    params = {"6099:01": 20000, "6099:02": 2000, "609A": 200000, **PLANT[model]}
    plant = {"module": {"0": {"kind": "FIELDBUS", "cycle_ms": cycle_ms, "drive": {"1": {
        "model": model, "image": 1000, "neg_limit": -100000, "pos_limit": 200000,
        "home_switch": [10000, 12000], "index_period": 2000, "index_phase": 500,
        "params": params}}}}}
    h = plc_factory([RIG, str(LIB)], plant=plant, scan_ms=scan_ms,
                    watch=["M0.0", "M1.1", "M2.1", "VW1000", "VW1032", "VD1036"])
    h.scan()
    return Rig(h, model)


@pytest.fixture(params=MODELS)
def rig(request, plc_factory) -> Rig:
    return make_rig(plc_factory, request.param)


# ---------------------------------------------------------------- DRV_POWER
def test_power_walks_6_7_f_one_step_per_scan(rig):
    """Each scan reads the state the last bus cycles left and sends the
    next command: 16#06, 16#07, 16#0F (HCFA §7.2 transitions 2, 3, 4);
    Ready in the scan that reads OPERATION ENABLED."""
    h = rig.h
    h["I0.0"] = 1
    seen = []
    for _ in range(4):
        h.scan()
        seen.append((rig.drive.state, h["VB10"], h["M0.0"]))
    assert seen == [("READY TO SWITCH ON", 0x06, 0), ("SWITCHED ON", 0x07, 0),
                    ("OPERATION ENABLED", 0x0F, 0), ("OPERATION ENABLED", 0x0F, 1)]
    assert rig.image("sw") == 0x8637 if rig.model == "hcfa-am0520b" else 0x0637


def test_power_off_disables_voltage_and_keeps_the_motion_bits(rig):
    """Enable = 0 clears bits 0..3 only: bits 4..8 of 6040h belong to the
    motion blocks (a relative move leaves bits 5 and 6)."""
    rig.enable()
    assert rig.move(1000, relative=True) == "M2.1"
    assert rig.image("cw") == 0x006F
    rig.h["I0.0"] = 0
    rig.h.scan(2)
    assert rig.image("cw") == 0x0060
    assert (rig.drive.state, rig.h["M0.0"], rig.h["VB10"]) == ("SWITCH ON DISABLED", 0, 0)


def test_the_library_leaves_the_accumulators_and_the_free_image_bytes_alone(rig):
    h = rig.h
    for i in range(77, 80):
        h[f"VB{1000 + i}"] = 0xA0 + i
    rig.enable()
    assert rig.home(19) == "M1.1"
    assert rig.move(5000) == "M2.1"
    assert rig.read(0x6099, 1) == "M4.1"
    assert rig.write(0x6099, 2, 2500) == "M5.1"
    assert [u16(h[f"VD{a}"] >> 16) for a in (80, 84, 88, 92)] == \
        [0x0A0A, 0x1B1B, 0x2C2C, 0x3D3D]
    assert [h[f"VD{a}"] & 0xFFFF for a in (80, 84, 88, 92)] == [0x0A0A, 0x1B1B, 0x2C2C, 0x3D3D]
    assert [h[f"VB{1000 + i}"] for i in range(77, 80)] == [0xA0 + i for i in range(77, 80)]


# ---------------------------------------------------------------- DRV_HOME
def test_home_method_19_ends_on_the_switch_edge_with_the_offset(rig):
    """607Ch = 250 written with DRV_WRITE, then method 19 (home switch
    10000..12000 as a positive level switch, home at its edge 9999): the
    count reads +607Ch there on the HCFA drive and -607Ch on the Kinco
    drive with 6099h:05 = 1; bits 12 and 10 (and Kinco's bit 15) stay
    set, bit 4 is low again."""
    rig.enable()
    assert rig.write(0x607C, 0, 250) == "M5.1"
    h = rig.h
    h["VW12"] = 19
    h["I0.1"] = 1
    h.scan()
    assert (h["M1.0"], rig.image("mode"), rig.image("method")) == (1, 6, 19)
    h.run_until("M1.1", timeout=20)
    assert (rig.drive.position, rig.drive.velocity) == (OFFSET_250[rig.model], 0)
    assert rig.image("position") == OFFSET_250[rig.model]
    assert rig.image("sw") == HOMED[rig.model] and rig.drive.statusword == HOMED[rig.model]
    assert rig.image("cw") & 0x10 == 0
    assert (h["M1.0"], h["M1.1"], h["M1.2"]) == (0, 1, 0)
    h["I0.1"] = 0
    h.scan()
    assert (h["M1.0"], h["M1.1"], h["M1.2"]) == (0, 0, 0)


def test_a_second_homing_runs_again(rig):
    """The attained bits of the first homing are not taken for the second:
    the block waits one call after raising bit 4."""
    rig.enable()
    assert rig.home(19) == "M1.1"
    assert rig.move(-30000) == "M2.1"
    started = rig.h.time
    assert rig.home(19) == "M1.1"
    assert rig.h.time - started > 1.0
    assert rig.drive.position == 0


def test_home_with_the_drive_disabled_is_an_error_at_once(rig):
    h = rig.h
    h["VW12"] = 19
    h["I0.1"] = 1
    h.scan()
    assert (h["M1.0"], h["M1.1"], h["M1.2"]) == (0, 0, 1)
    assert rig.image("mode") == 1                    # nothing written to the drive


def test_home_on_an_active_limit_the_method_does_not_use_is_a_homing_error(plc_factory):
    """Method 18 (search + to PLS) starting on NLS: 6041h bit 13, no fault
    (HCFA §7.5.4); Error, bit 4 low."""
    plant = {"module": {"0": {"kind": "FIELDBUS", "drive": {"1": {
        "model": "hcfa-am0520b", "image": 1000, "neg_limit": 0, "pos_limit": 20000,
        "params": {"6099:01": 20000, "6099:02": 2000, "609A": 200000}}}}}}
    h = plc_factory([RIG, str(LIB)], plant=plant)
    rig = Rig(h, "hcfa-am0520b")
    rig.enable()
    assert rig.home(18) == "M1.2"
    assert rig.drive.statusword & 0x2000 and rig.drive.error_code == 0
    assert rig.drive.state == "OPERATION ENABLED" and rig.image("cw") & 0x10 == 0


@pytest.mark.parametrize("model", MODELS)
def test_with_scans_faster_than_the_bus_cycle_a_second_homing_still_runs(plc_factory, model):
    """1 ms scans, 4 ms bus cycle: the scan after bit 4 rose still reads
    the attained word of the first homing; the block waits for the bus
    cycle counter to move, so the second homing runs (the drive logs two
    starts) and ends on the same home point."""
    rig = make_rig(plc_factory, model, scan_ms=1, cycle_ms=4)
    rig.enable()
    assert rig.home(19) == "M1.1"
    first = rig.h.time
    assert rig.home(19) == "M1.1"
    starts = [e for e in rig.sim.log if "homing method 19 started" in e.text]
    assert len(starts) == 2 and starts[1].t_us > first * 1e6
    assert rig.drive.position == 0 and rig.drive.statusword == HOMED[model]


# ---------------------------------------------------------------- DRV_MOVE
def test_absolute_then_relative_moves_end_exactly_on_their_targets(rig):
    rig.enable()
    h = rig.h
    assert rig.move(50000) == "M2.1"
    assert (rig.drive.position, rig.image("position"), rig.drive.velocity) == (50000, 50000, 0)
    assert rig.image("sw") == PP_IDLE[rig.model]
    assert rig.image("cw") == 0x002F                 # bit 5 set, bit 4 low again
    assert rig.move(-20000, relative=True) == "M2.1"
    assert rig.drive.position == 30000 and rig.image("cw") == 0x006F
    assert rig.move(-7, relative=True) == "M2.1"
    assert rig.drive.position == 29993
    assert h["M2.2"] == 0


def test_move_handshake_bit_4_rises_after_6061h_shows_pp_and_falls_on_the_acknowledge(rig):
    rig.enable()
    h = rig.h
    h["VD40"] = 100000
    h["I0.2"] = 1
    trace = []
    for _ in range(4):
        h.scan()
        trace.append((rig.image("cw") & 0x70, u16(rig.image("sw")) & 0x1400, h["M2.0"]))
    # scan 1: set-point written, bit 4 low (6061h already 1); scan 2: bit 4
    # high; the drive acknowledges (bit 12) at the next bus cycle; scan 3:
    # bit 4 falls; moving: bit 10 low
    assert trace == [(0x20, 0x0400, 1), (0x30, 0x1000, 1), (0x20, 0x0000, 1),
                     (0x20, 0x0000, 1)]
    h.run_until("M2.1", timeout=10)
    assert rig.drive.position == 100000


def test_a_move_into_a_limit_switch_ends_in_error(rig):
    """Target beyond PLS (200000): the axis stops at the switch, 6041h bits
    10 and 11: Error; a further move toward it is refused without an
    acknowledge (bit 11): Error; a move away is done."""
    rig.enable()
    assert rig.move(250000) == "M2.2"
    assert rig.drive.position == 200000 and rig.drive.statusword & 0x0C00 == 0x0C00
    assert rig.move(210000) == "M2.2"
    assert rig.drive.position == 200000
    assert rig.move(150000) == "M2.1"
    assert rig.drive.position == 150000


@pytest.mark.parametrize("model", MODELS)
def test_with_scans_faster_than_the_bus_cycle_a_move_off_a_limit_is_done(plc_factory, model):
    """1 ms scans, 4 ms bus cycle: after a stop at PLS the statusword
    shows bit 11 until the drive has taken the move away from it; the
    block judges the refusal bits only after a bus cycle, so the move is
    done, not refused."""
    rig = make_rig(plc_factory, model, scan_ms=1, cycle_ms=4)
    rig.enable()
    assert rig.move(250000) == "M2.2"
    assert rig.move(150000) == "M2.1"
    assert rig.drive.position == 150000


def test_a_move_with_a_zero_profile_is_refused(rig):
    """6081h = 0: the drive refuses the set-point with bit 14 (HCFA
    §7.5.3): Error, the axis does not move."""
    rig.enable()
    rig.h["VD44"] = 0
    assert rig.move(5000) == "M2.2"
    assert rig.drive.position == 0 and rig.drive.statusword & 0x4000


def test_disabling_during_a_move_is_an_error(rig):
    rig.enable()
    h = rig.h
    h["VD40"] = 150000
    h["I0.2"] = 1
    h.run("0.5s")
    assert h["M2.0"] == 1
    h["I0.0"] = 0
    h.run_until("M2.2", timeout=1)
    assert rig.image("cw") & 0x10 == 0


# ---------------------------------------------------------------- DRV_VEL
def test_velocity_runs_reaches_its_speed_and_ramps_to_rest(rig):
    """PV at -30000 counts/s, 200000 counts/s²: InVelocity after the 0.15 s
    ramp; Enable off: 60FFh = 0 in the image, the axis ramps to rest on
    6084h and the drive stays in PV."""
    rig.enable()
    h = rig.h
    h["VD56"] = -30000
    h["I0.4"] = 1
    h.scan()
    assert (rig.image("mode"), rig.image("velocity"), h["M3.1"]) == (3, -30000, 1)
    # the ramp runs from the bus cycle after that scan for 0.15 s; the scan
    # 0.16 s after it reads bit 10
    assert h.run_until("M3.0", timeout=2) == pytest.approx(0.16)
    assert rig.drive.velocity == -30000 and rig.drive.mode == 3
    h["VD56"] = 10000                                # a new speed on the fly
    h.run_until(lambda: rig.drive.velocity == 10000, timeout=1)
    h["I0.4"] = 0
    h.scan()
    assert rig.image("velocity") == 0 and (h["M3.0"], h["M3.1"]) == (0, 0)
    h.run_until(lambda: rig.drive.velocity == 0, timeout=1)
    assert rig.drive.mode == 3 and rig.drive.state == "OPERATION ENABLED"


def test_velocity_waits_for_the_drive_and_fails_when_it_is_lost(rig):
    """Enable before the drive is enabled: the block waits, then runs.  A
    fault while running: Error, 60FFh = 0 (a reset does not start the
    axis again), until Enable falls."""
    h = rig.h
    h["VD56"] = 20000
    h["I0.4"] = 1
    h.scan(3)
    assert (h["M3.1"], h["M3.2"], rig.drive.velocity) == (0, 0, 0)
    rig.enable()
    h.run_until("M3.0", timeout=2)
    rig.sim.fault(rig.sim.now, 20704, 20704, "over-current (test)")
    h.scan(2)
    assert (h["M3.1"], h["M3.2"], rig.image("velocity")) == (0, 1, 0)
    h["I0.4"] = 0
    h.scan()
    assert h["M3.2"] == 0


# ---------------------------------------------------------------- SDO
def test_read_and_write_parameters(rig):
    rig.enable()
    h = rig.h
    assert rig.read(0x6099, 1) == "M4.1"
    assert h["VD20"] == 0                             # valid only while Done
    h["VW60"], h["VB62"] = 0x6099, 1
    h["I0.5"] = 1
    h.run_until("M4.1", timeout=1)
    assert (h["VD20"], h["VD24"]) == (20000, 0)
    h["I0.5"] = 0
    assert rig.write(0x607C, 0, -250) == "M5.1"
    assert rig.sim.read(0x607C) == -250 and h["VD28"] == 0


@pytest.mark.parametrize("index,sub,value,abort", [
    (0x6007, 0, 0, 0x06020000),            # no such object
    (0x6041, 0, 1, 0x06010002),            # read-only
    (0x6060, 0, 300, 0x06070010),          # 6060h is I8: 300 does not fit
])
def test_a_refused_write_shows_the_abort_code(rig, index, sub, value, abort):
    rig.enable()
    h = rig.h
    h["VW70"], h["VB72"], h["VD64"] = index, sub, value
    h["I0.6"] = 1
    h.run_until("M5.2", timeout=1)
    assert h["VD28"] & 0xFFFFFFFF == abort
    assert any(f"0x{abort:08X}" in d.message for d in h.diagnostics)


def test_a_read_and_a_write_started_together_take_turns(rig):
    """Both edges in one scan: DRV_READ takes the mailbox, DRV_WRITE waits
    (Busy) until the module has cleared the read's done flag, then writes."""
    h = rig.h
    h["VW60"], h["VB62"] = 0x6099, 2
    h["VW70"], h["VB72"], h["VD64"] = 0x6099, 2, 3000
    h["I0.5"] = h["I0.6"] = 1
    h.scan()
    assert (h["M4.0"], h["M5.0"], rig.image("status") & 0x0E) == (1, 1, 0x04)
    h.scan()
    assert (h["M4.1"], h["VD20"], h["M5.0"]) == (1, 2000, 1)   # the value before the write
    h.run_until("M5.1", timeout=1)
    assert rig.sim.read(0x6099, 2) == 3000


# ---------------------------------------------------------------- DRV_RESET
def test_a_fault_and_its_reset(rig):
    """Homing method 15 is no method of either model: alarm 62, FAULT
    (HCFA §7.5.4); DRV_HOME Error, DRV_POWER Fault.  DRV_RESET holds bit 7
    until the fault is gone; DRV_POWER, still enabled, brings the drive
    back to OPERATION ENABLED."""
    rig.enable()
    h = rig.h
    assert rig.home(15) == "M1.2"
    assert (rig.drive.state, rig.drive.error_code) == ("FAULT", 62)
    assert (h["M0.0"], h["M0.1"]) == (0, 1)
    h["I0.7"] = 1
    h.scan()
    assert (h["M6.0"], rig.image("cw") & 0x80) == (1, 0x80)
    h.scan()
    assert (h["M6.0"], h["M6.1"], rig.image("cw") & 0x80) == (0, 1, 0)
    # the fault left at the first cycle (transition 15); in the same scan
    # as bit 7 falls DRV_POWER, still enabled, sent Shutdown
    assert (rig.drive.state, rig.drive.error_code) == ("READY TO SWITCH ON", 0)
    h["I0.7"] = 0
    h.run_until("M0.0", timeout=1)
    assert (h["M0.1"], h["M6.1"]) == (0, 0)
    assert rig.move(1000) == "M2.1"


def test_reset_without_a_fault_is_done_at_once(rig):
    rig.enable()
    rig.h["I0.7"] = 1
    rig.h.scan()
    assert (rig.h["M6.0"], rig.h["M6.1"], rig.image("cw") & 0x80) == (0, 1, 0)


def test_a_fault_that_needs_a_power_cycle_keeps_reset_busy_until_execute_falls(rig):
    """Over-current (alarm 20704) is reset only by a power cycle (HCFA
    §4.7): bit 7 stays high and the block Busy; Execute low: bit 7 falls,
    the block is idle, the drive still in FAULT."""
    rig.enable()
    rig.sim.fault(rig.sim.now, 20704, 20704, "over-current (test)")
    h = rig.h
    h.scan(2)                           # the image shows it after the next scan
    assert rig.h["M0.1"] == 1
    h["I0.7"] = 1
    h.scan(5)
    assert (h["M6.0"], h["M6.1"], rig.image("cw") & 0x80) == (1, 0, 0x80)
    h["I0.7"] = 0
    h.scan()
    assert (h["M6.0"], h["M6.1"], rig.image("cw") & 0x80) == (0, 0, 0)
    assert rig.drive.state == "FAULT"


@pytest.mark.parametrize("model", MODELS)
def test_with_scans_faster_than_the_bus_cycle_a_reset_retried_at_once_reaches_the_drive(
        plc_factory, model):
    """1 ms scans, 4 ms bus cycle, a fault only a power cycle clears:
    reset pressed (bit 7 high), dropped in the scan at 22 ms and pressed
    again at 23 ms, before the next cycle.  The block raises bit 7 again
    only after the cycle at 24 ms has carried it low, so the drive sees a
    second 0->1 edge at 28 ms (and refuses it again, saying why)."""
    rig = make_rig(plc_factory, model, scan_ms=1, cycle_ms=4)
    rig.enable()
    h = rig.h
    rig.sim.fault(rig.sim.now, 20704, 20704, "over-current (test)")
    h.run_until("M0.1", timeout=1)
    assert round(h.time * 1000) == 17                 # the next scan begins at 17 ms
    trace = []
    for i in range(12):
        h["I0.7"] = int(i != 5)
        h.scan()
        trace.append((round(h.time * 1000) - 1, h["M6.0"], rig.image("cw") & 0x80))
    assert trace == [(17, 1, 0x80), (18, 1, 0x80), (19, 1, 0x80), (20, 1, 0x80), (21, 1, 0x80),
                     (22, 0, 0), (23, 1, 0), (24, 1, 0x80), (25, 1, 0x80), (26, 1, 0x80),
                     (27, 1, 0x80), (28, 1, 0x80)]
    refused = [e.t_us for e in rig.sim.log if "Fault reset refused" in e.text]
    assert refused == [20_000, 28_000]
