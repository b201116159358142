"""Statements of the HCFA AM0520B manual (§7, §8.3) that the other CiA 402
tests do not pin, each test naming its section; docs/cia402.md ("Audit
against the manuals") lists every statement of the manual with its test or
decision."""

from __future__ import annotations

import pytest

from plcrt.devices.cia402.drive import Drive
from plcrt.devices.cia402.plant import DrivePlant

from cia402_drive_helpers import enable

HCFA = "hcfa-am0520b"


def pp_move(d: Drive, target: int) -> None:
    d.write(0x607A, 0, target)
    d.write(0x6040, 0, 0x1F)
    d.write(0x6040, 0, 0x0F)


# ---------------------------------------------------------------- §7.4.1: bits by mode

def test_csp_ignores_the_halt_bit():
    """§7.4.1, bits 8 and 6–4 by mode: in CSP bit 8 (halt) is "无效": the
    axis follows 607Ah with bit 8 set as without it."""
    d = enable(Drive(HCFA), 8)
    d.write(0x6040, 0, 0x010F)
    for k in range(1, 11):
        d.write(0x607A, 0, 100 * k)
        d.cycle(d.now + 1000)
    assert d.position == 900 and d.read(0x6062) == 1000
    d.cycle(d.now + 1000)
    assert d.position == 1000 and not d.statusword & 0x0100


def test_pv_ignores_bits_4_to_6():
    """§7.4.1 / §7.6.2: bits 6–4 are "无效" in PV; the axis runs at 60FFh as
    soon as it is enabled, whatever they hold."""
    runs = []
    for cw in (0x0F, 0x1F, 0x2F, 0x4F, 0x7F):
        d = enable(Drive(HCFA), 3, x6083=100_000, x6084=100_000)
        d.write(0x6040, 0, cw)
        d.write(0x60FF, 0, 10_000)
        d.advance(200_000)
        runs.append((d.read(0x606C), d.position))
    assert runs == [(10_000, 1500)] * 5


# ---------------------------------------------------------------- §7.5.1 / §7.6.1: 6080h

def test_6080h_caps_the_speed_in_pp_and_pv():
    """§7.5.1 / §7.6.1: 6080h, the maximum motor speed, acts in PP and PV: a
    profile speed 6081h or target 60FFh above it runs at 6080h."""
    d = enable(Drive(HCFA), 1, x6081=50_000, x6083=1_000_000, x6084=1_000_000, x6080=20_000)
    pp_move(d, 100_000)
    d.advance(1_000_000)
    assert d.read(0x606C) == 20_000
    d = enable(Drive(HCFA), 3, x6083=1_000_000, x6084=1_000_000, x6080=20_000)
    d.write(0x60FF, 0, -50_000)
    d.advance(1_000_000)
    assert d.read(0x606C) == -20_000


def test_6080h_caps_a_csp_step():
    """§7.5.1: 6080h acts in CSP: a set-point step larger than 6080h × cycle
    is followed at 6080h (decision "CSP interpolation": at most at 6080h)."""
    d = enable(Drive(HCFA), 8, x6080=100_000)
    d.write(0x607A, 0, 1000)                    # 1000 counts in 1 ms = 10^6 P/s
    d.cycle(d.now + 1000)
    d.cycle(d.now + 1000)
    assert d.position == 100                      # 100 000 P/s for 1 ms


# ---------------------------------------------------------------- §7.5.1 / §8.3: 6062h

def test_6062h_is_the_position_demand():
    """§7.5.1, §8.3: 6062h is the command position: in PP it runs with the
    profile, and ahead of 6064h when a mechanical end holds the axis."""
    d = enable(Drive(HCFA, plant=DrivePlant(pos_stop=5000)), 1, x6081=20_000,
               x6083=100_000, x6084=100_000)
    pp_move(d, 10_000)
    d.advance(300_000)
    assert d.read(0x6062) == d.read(0x6064) == 4000
    d.advance(400_000)                           # time is absolute: 0.4 s
    assert d.read(0x6064) == 5000 and d.read(0x6062) == 6000
    d.advance(700_000)
    assert d.read(0x6064) == 5000 and d.read(0x6062) == 10_000


# ---------------------------------------------------------------- §7.5.4: the error table

_PLANT = dict(neg_limit=-20_000, pos_limit=20_000, home_switch=(5000, 6000), index_period=1000)
NLS_ERROR = [2, 7, 8, 9, 10, 23, 24, 25, 26]        # "use PLS, NLS active"
PLS_ERROR = [1, 11, 12, 13, 14, 27, 28, 29, 30]     # "use NLS, PLS active"
NO_LIMIT = [3, 4, 19, 20]                           # "use no limit, a limit active"


def homing_from(n: int, start: int, **plant: object) -> Drive:
    """A HCFA drive at *start* (plant frame) homing with method *n*."""
    keys = dict(_PLANT)
    keys.update(plant)
    shifted = {k: (tuple(x - start for x in v) if isinstance(v, tuple) else v - start)
               for k, v in keys.items() if k != "index_period"}
    p = DrivePlant(index_period=1000, index_phase=-start % 1000, **shifted)
    d = enable(Drive(HCFA, plant=p), 6, x6098=n, x6099_01=20_000, x6099_02=5000,
               x609A=200_000)
    d.write(0x6040, 0, 0x1F)
    d.advance(2_000_000)
    return d


@pytest.mark.parametrize("n", NLS_ERROR + PLS_ERROR + NO_LIMIT)
def test_hm_limit_errors_of_the_7_5_4_table(n):
    """§7.5.4 (三): a limit switch active that the method does not use is a
    homing error (statusword bit 13, 0x2637 at rest): NLS for methods 2,
    7–10, 23–26; PLS for 1, 11–14, 27–30; either for 3, 4, 19, 20."""
    starts = []
    if n in NLS_ERROR or n in NO_LIMIT:
        starts.append(-20_000)                       # on the NLS
    if n in PLS_ERROR or n in NO_LIMIT:
        starts.append(20_000)                        # on the PLS
    for start in starts:
        d = homing_from(n, start)
        assert d.statusword & 0x3400 == 0x2400, (n, start, hex(d.statusword))
        assert d.read(0x603F) == 0


@pytest.mark.parametrize("n", [33, 34])
@pytest.mark.parametrize("start", [-20_000, 20_000, 5500])
def test_hm_index_methods_fail_on_a_limit_or_the_home_switch(n, start):
    """§7.5.4 (三): methods 33, 34 use the index alone: a limit or the home
    switch active is a homing error (bit 13)."""
    d = homing_from(n, start)
    assert d.statusword & 0x2000, hex(d.statusword)


# ---------------------------------------------------------------- §7.6.2: bit 12 in PV

def test_pv_bit_12_is_set_from_the_halt_on_while_slowing_to_zero():
    """§7.6.2 bit 12 "speed 0, or about to decelerate to 0" and note *1 (a
    halt or a limit): bit 12 rises with the halt, before the speed is 0."""
    d = enable(Drive(HCFA), 3, x6083=100_000, x6084=100_000)
    d.write(0x60FF, 0, 10_000)
    d.advance(200_000)
    assert not d.statusword & 0x1000
    d.write(0x6040, 0, 0x010F)
    d.advance(201_000)
    assert d.read(0x606C) != 0 and d.statusword & 0x1000
    d.advance(400_000)
    assert d.read(0x606C) == 0 and d.statusword & 0x1000


# ---------------------------------------------------------------- §8.3: 60FDh

def test_60fdh_bits_are_nls_pls_and_home():
    """§8.3 60FDh: bit 0 negative limit, bit 1 positive limit, bit 2 home."""
    seen = {}
    for name, start in (("nls", -20_000), ("pls", 20_000), ("home", 5500), ("none", 0)):
        d = homing_from(35, start)
        seen[name] = d.read(0x60FD) & 0x7
    assert seen == {"nls": 1, "pls": 2, "home": 4, "none": 0}


# ---------------------------------------------------------------- §7.3: the mode table

def walk(mode: int, steps: list[tuple[str, object]]) -> list[int]:
    """Statuswords of a HCFA drive after each step: ("cw", word), ("at", t µs
    absolute), ("set", (index, value)) or ("fault", code)."""
    d = Drive(HCFA)
    d.write(0x6060, 0, mode)
    for index, value in ((0x6081, 20_000), (0x6083, 100_000), (0x6084, 100_000)):
        d.write(index, 0, value)
    out = []
    for kind, arg in steps:
        if kind == "cw":
            d.write(0x6040, 0, arg)
            d.cycle(d.now)
        elif kind == "at":
            d.advance(arg)
        elif kind == "set":
            d.write(arg[0], 0, arg[1])
        else:
            d.inject_fault(arg)
            d.cycle(d.now + 1000)
        out.append(d.statusword)
    return out


ENABLE = [("cw", 0x00), ("cw", 0x06), ("cw", 0x07)]


def test_7_3_pp_column():
    """§7.3, PP (6060h = 1): 00h 0650h, 06h 0631h, 07h 0633h, 0Fh 8637h; a
    set-point with bit 4 held 1237h, bit 4 released while moving 8237h, halt
    10Fh at rest 0737h, over-voltage 0638h."""
    got = walk(1, ENABLE + [("cw", 0x0F), ("set", (0x607A, 10_000)), ("cw", 0x3F),
                            ("at", 100_000), ("cw", 0x2F), ("at", 1_000_000), ("cw", 0x10F),
                            ("fault", 12827)])
    assert [got[k] for k in (0, 1, 2, 3, 5, 7, 9, 10)] == [
        0x0650, 0x0631, 0x0633, 0x8637, 0x1237, 0x8237, 0x0737, 0x0638]


def test_7_3_pv_column():
    """§7.3, PV (6060h = 3): running at 60FFh and changing speed 0237h (at
    60FFh: bit 10, 0637h, §7.6.2),
    over-voltage 0638h; where §7.3 prints 0237h enabled at rest and 0737h
    halted at rest, §7.6.2's bit 12 (speed 0) gives 1637h and 1737h
    (decision "§7.6.2 vs §7.3")."""
    got = walk(3, ENABLE + [("cw", 0x0F), ("set", (0x60FF, 10_000)), ("at", 50_000),
                            ("at", 150_000), ("set", (0x60FF, 5000)), ("at", 175_000),
                            ("cw", 0x10F), ("at", 400_000), ("fault", 12827)])
    assert got[:3] == [0x0650, 0x0631, 0x0633]
    assert [got[k] for k in (3, 5, 6, 8, 10, 11)] == [0x1637, 0x0237, 0x0637, 0x0237, 0x1737,
                                                      0x0638]


def test_7_3_csp_column():
    """§7.3, CSP (6060h = 8): 06h 0631h, 07h 0633h, enabled 1637h, moving
    1237h, stopped 1637h."""
    d = Drive(HCFA)
    got = []
    for cw in (0x06, 0x07, 0x0F):
        d.write(0x6040, 0, cw)
        d.cycle(d.now + 1000)
        got.append(d.statusword)
    d.write(0x607A, 0, 500)
    d.cycle(d.now + 1000)
    got.append(d.statusword)
    d.cycle(d.now + 1000)
    d.cycle(d.now + 1000)
    got.append(d.statusword)
    assert got == [0x0631, 0x0633, 0x1637, 0x1237, 0x1637]


# ---------------------------------------------------------------- §5.1 / §8.2: P18

def test_p18_37_and_39_read_the_al_code_and_the_402_state():
    """§5.1 / §8.2: P18.37 "ECAT bus error code" is the AL status code of
    the last refused ESM change (ETG.1000.6), P18.39 "CoE 402 state" the
    statusword 6041h; both read live, not 0."""
    d = Drive(HCFA)
    d.esm.request(8, 0.0)                               # INIT -> OP skips states: 0x0011
    assert d.read(0x2012, 37) == 0x0011
    d.write(0x6040, 0, 0x06)
    assert d.read(0x2012, 39) == d.statusword == 0x0631        # §7.3, CSP


# ---------------------------------------------------------------- §4.7: every alarm by name

@pytest.mark.parametrize("name,code,resettable", [
    ("parameter_storage", 4, False), ("communication", 17, False), ("phase_loss", 8, False),
    ("power_stage", 20640, False), ("overcurrent", 20704, False), ("under_voltage", 12828, False),
    ("over_voltage", 12827, True), ("encoder", 10256, True)])
def test_every_4_7_alarm_by_name_with_its_reset_rule(name, code, resettable):
    """§4.7: each alarm the table names (by the names of `inject_fault`)
    shows its number in 603Fh; "是" clears with a reset (15), "否" only
    with a power cycle."""
    d = enable(Drive(HCFA), 3)
    assert d.inject_fault(name) == code and d.read(0x603F) == code
    d.cycle(d.now + 1000)
    d.write(0x6040, 0, 0x00)
    d.write(0x6040, 0, 0x80)
    d.cycle(d.now + 1000)
    assert (d.read(0x603F) == 0) is resettable
    d.power_cycle()
    assert d.read(0x603F) == 0


def test_60c5h_60c6h_do_not_act_in_pv():
    """§7.5.1 gives 60C5h / 60C6h to PP and HM ("—" for CSP), §7.6.1 does
    not list them for PV: PV ramps on 6083h above 60C5h unchanged."""
    d = enable(Drive(HCFA), 3, x6083=400_000, x6084=400_000, x60C5=100_000, x60C6=100_000)
    d.write(0x60FF, 0, 40_000)
    d.advance(50_000)
    assert d.read(0x606C) == 20_000                 # 400 000 P/s² for 50 ms
    assert not any("60C5h" in e.text for e in d.log)
