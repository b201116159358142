"""Statements of the Kinco servo homing note that the other CiA 402 tests do
not pin, each test naming its section; docs/cia402.md ("Audit against the
manuals") lists every statement of the note with its test or decision."""

from __future__ import annotations

from plcrt.devices.cia402.drive import Drive
from plcrt.devices.cia402.od import ObjectDictionary
from plcrt.devices.cia402.plant import DrivePlant

from cia402_drive_helpers import enable

KINCO = "kinco-servo"


def test_kinco_2_1_factory_values():
    """Kinco §2.1: 6099h:03 power-on homing "0: factory default"; §2.4:
    the index blind zone "defaults to 0" (0, ¼, ½ revolution)."""
    od = ObjectDictionary.load(KINCO)
    assert od.entry(0x6099, 3).default == 0 and od.entry(0x6099, 6).default == 0
    assert (od.entry(0x6099, 6).low, od.entry(0x6099, 6).high) == (0, 2)


def test_kinco_method_1_as_2_2_describes_it():
    """Kinco §2.2, method 1: start negative at 6099h:01 (the turning-signal
    speed), reverse on the NLS rising edge at 6099h:02 (the signal speed),
    stop at the next index and set the position to 0."""
    plant = DrivePlant(neg_limit=-10_000, pos_limit=50_000, index_period=1000, index_phase=300)
    d = enable(Drive(KINCO, plant=plant), 6, x6098=1, x6099_01=20_000, x6099_02=2000,
               x609A=400_000)
    d.write(0x6040, 0, 0x1F)
    d.advance(100_000)
    assert d.read(0x606C) == -20_000                  # the search, negative, at 6099h:01
    speeds = []
    for t in range(100_000, 3_000_000, 10_000):
        d.advance(t)
        speeds.append(d.read(0x606C))
    assert 2000 in speeds and max(speeds) == 2000     # back, positive, at 6099h:02
    assert d.statusword & 0x9400 == 0x9400            # bits 15 (reference found), 10
    assert d.position == 0
    assert d.axis.mechanical(d.now) == -9700          # the first index right of the NLS


def test_kinco_2_6_statusword_bits_in_pp():
    """Kinco §2.6: bits 0–6 the CiA 402 state (operation enabled 0x27 with
    bit 5 quick stop = 1), bit 9 remote, bit 12 set-point acknowledge, bit 10
    target reached, bit 11 a limit switch with bit 8 (manufacturer bit 0:
    the abnormal stop, as on the HCFA drive); bit 7 (warning) never set."""
    d = enable(Drive(KINCO, plant=DrivePlant(pos_limit=5000)), 1, x6081=20_000,
               x6083=100_000, x6084=100_000)
    sw = d.statusword
    assert sw & 0x6F == 0x27 and sw & 0x0200 and sw & 0x0400
    d.write(0x607A, 0, 2000)
    d.write(0x6040, 0, 0x1F)
    assert d.statusword & 0x1000 and not d.statusword & 0x0400
    d.write(0x6040, 0, 0x0F)
    d.advance(1_000_000)
    assert d.position == 2000 and d.statusword & 0x0400
    d.write(0x607A, 0, 9000)
    d.write(0x6040, 0, 0x1F)
    d.write(0x6040, 0, 0x0F)
    d.advance(3_000_000)
    assert d.position == 5000 and d.statusword & 0x0900 == 0x0900    # bit 8: the limit stop
    assert not d.statusword & 0x0080 and not sw & 0x0080
