"""Plant files (plcrt.devices.plant) and the EM253 module's terminals.

The plant file describes the machine around each EM253 axis; every mistake
in it is a :class:`plcrt.PlcConfigError` naming the key.  The module maps
its terminals into the process image (16 DI / 16 DO per module, manual
chapter 1): for a CPU 226 and slot 0 the inputs of axis 0/1 are IB3/IB4
(.0 STF, .1 RPS, .2 L+, .3 L-, .4 Z) and the outputs QB2/QB3 (.0 En,
.1 CLR, .2 P, .3 D).  docs/em253.md describes the format and the map.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt
from plcrt.devices.em253.axis import AxisPlant
from plcrt.devices.plant import load_plant

ROOT = Path(__file__).resolve().parents[2]

VALID = """\
# a commented plant
[module.0]
kind = "em253"
[module.0.axis.0]
start = 50000
rps = [10000, 20000]
limit_neg = -100000
limit_pos = 400000
z_period = 4000
z_offset = 1000
events = [ { at = 2.5, input = "STF", value = true },
           { at = 0.000001, input = "stf", value = false } ]
[module.0.axis.1]
[module.3.axis.1]
start = -7
"""


# ---------------------------------------------------------------------------
# Loader
# ---------------------------------------------------------------------------

def test_valid_plant_text() -> None:
    plant = load_plant(VALID, file="m.toml")
    assert plant.file == "m.toml"
    assert sorted(plant.modules) == [0, 3]
    m0 = plant.modules[0]
    assert (m0.slot, m0.kind, sorted(m0.axes)) == (0, "EM253", [0, 1])
    ax = m0.axes[0]
    assert ax == AxisPlant(start=50000, rps=(10000, 20000), limit_neg=-100000,
                           limit_pos=400000, z_period=4000, z_offset=1000,
                           events=[(1, "STF", False), (2_500_000, "STF", True)])
    assert m0.axes[1] == AxisPlant()
    assert plant.modules[3].axes[1].start == -7
    assert plant.modules[3].axes.keys() == {1}


def test_valid_plant_file_dict_and_path(tmp_path: Path) -> None:
    """The same plant from a file path (str or Path) and from a parsed dict."""
    f = tmp_path / "plant.toml"
    f.write_text(VALID, encoding="utf-8")
    from_text = load_plant(VALID)
    for plant in (load_plant(f), load_plant(str(f))):
        assert plant.file == str(f)
        assert plant.modules == from_text.modules
    d = {"module": {"0": {"axis": {"0": {"start": 5, "rps": [1, 2]}}}}}
    assert load_plant(d).modules[0].axes[0] == AxisPlant(start=5, rps=(1, 2))


def test_empty_plant_has_no_modules() -> None:
    assert load_plant({}).modules == {}
    assert load_plant("# nothing\n[module]\n").modules == {}


def test_the_example_plant_loads() -> None:
    plant = load_plant(ROOT / "programs" / "em253" / "plant.toml")
    assert sorted(plant.modules[0].axes) == [0, 1]
    assert plant.modules[0].axes[0].limit_neg == -2_000_000


def test_rps_of_one_position_is_allowed() -> None:
    assert load_plant({"module": {"0": {"axis": {"0": {"rps": [5, 5]}}}}}) \
        .modules[0].axes[0].rps == (5, 5)


ERROR_CASES = [
    # (id, plant text, fragments the message must contain)
    ("module not a table", "module = 3\n", ["[module]"]),
    ("slot above 6", "[module.7]\n", ["module.7", "0..6"]),
    ("slot not a number", "[module.x]\n", ["module.x", "0..6"]),
    ("unknown kind", "[module.0]\nkind = 'EM235'\n", ["module.0", "EM235"]),
    ("axis 2", "[module.0.axis.2]\n", ["module.0.axis.2", "axes 0 and 1"]),
    ("unknown axis key", "[module.0.axis.0]\nlimit = 5\n", ["module.0.axis.0", "limit"]),
    ("start a float", "[module.0.axis.0]\nstart = 1.5\n", ["module.0.axis.0.start"]),
    ("start a bool", "[module.0.axis.0]\nstart = true\n", ["module.0.axis.0.start"]),
    ("rps three values", "[module.0.axis.0]\nrps = [1, 2, 3]\n", ["module.0.axis.0.rps"]),
    ("rps not a list", "[module.0.axis.0]\nrps = 4\n", ["module.0.axis.0.rps"]),
    ("rps a string", "[module.0.axis.0]\nrps = ['a', 2]\n", ["module.0.axis.0.rps"]),
    ("rps reversed", "[module.0.axis.0]\nrps = [5, 2]\n", ["module.0.axis.0.rps", "above"]),
    ("limit_neg a string", "[module.0.axis.0]\nlimit_neg = 'x'\n",
     ["module.0.axis.0.limit_neg"]),
    ("limit_pos a float", "[module.0.axis.0]\nlimit_pos = 1.0\n",
     ["module.0.axis.0.limit_pos"]),
    ("limits crossed", "[module.0.axis.0]\nlimit_neg = 5\nlimit_pos = 5\n",
     ["module.0.axis.0", "limit_neg", "limit_pos"]),
    ("z_period zero", "[module.0.axis.0]\nz_period = 0\n", ["module.0.axis.0.z_period"]),
    ("z_period negative", "[module.0.axis.0]\nz_period = -4\n", ["module.0.axis.0.z_period"]),
    ("z_offset a float", "[module.0.axis.0]\nz_offset = 0.5\n", ["module.0.axis.0.z_offset"]),
    ("event without input", "[module.0.axis.0]\nevents = [{ at = 1, value = true }]\n",
     ["module.0.axis.0.events[0]", "input"]),
    ("event of an unknown input",
     ("[module.0.axis.0]\nevents = [{ at = 1, input = 'STF', value = true },\n"
      "  { at = 1, input = 'RPS', value = true }]\n"),
     ["module.0.axis.0.events[1]", "STF"]),
    ("event at a negative time",
     "[module.0.axis.0]\nevents = [{ at = -1, input = 'STF', value = true }]\n",
     ["module.0.axis.0.events[0]"]),
    ("event time not a number",
     "[module.0.axis.0]\nevents = [{ at = 'soon', input = 'STF', value = true }]\n",
     ["module.0.axis.0.events[0]", "at"]),
    ("TOML syntax", "[module.0\n", ["p.toml"]),
    ("module entry not a table", "[module]\n0 = 5\n", ["module.0"]),
    ("axis not a table", "[module.0]\naxis = 5\n", ["module.0.axis"]),
    ("axis entry not a table", "[module.0.axis]\n0 = 5\n", ["module.0.axis.0"]),
    ("events not a list", "[module.0.axis.0]\nevents = 5\n", ["module.0.axis.0.events"]),
    ("misspelt top-level table", "[modules.0.axis.0]\nstart = 5\n", ["modules"]),
    ("unknown module key", "[module.0]\naxes = 1\n", ["module.0", "axes"]),
    ("event value a string",
     "[module.0.axis.0]\nevents = [{ at = 1, input = 'STF', value = 'false' }]\n",
     ["module.0.axis.0.events[0]", "value"]),
    ("event time not finite",
     "[module.0.axis.0]\nevents = [{ at = nan, input = 'STF', value = true }]\n",
     ["module.0.axis.0.events[0]", "at"]),
]


@pytest.mark.parametrize("text,fragments", [c[1:] for c in ERROR_CASES],
                         ids=[c[0] for c in ERROR_CASES])
def test_bad_plant_names_file_and_key(text: str, fragments: list[str]) -> None:
    with pytest.raises(plcrt.PlcConfigError) as info:
        load_plant(text, file="p.toml")
    msg = str(info.value)
    assert msg.startswith("error: p.toml: "), msg
    for fragment in fragments:
        assert fragment in msg, msg


def test_missing_plant_file_is_a_config_error(tmp_path: Path) -> None:
    missing = tmp_path / "nope.toml"
    with pytest.raises(plcrt.PlcConfigError) as info:
        load_plant(missing)
    assert str(missing) in str(info.value)


def test_load_passes_plant_errors_through() -> None:
    with pytest.raises(plcrt.PlcConfigError, match="module.9"):
        plcrt.load(_ob1(), plant={"module": {"9": {}}})


# ---------------------------------------------------------------------------
# Terminals in the process image
# ---------------------------------------------------------------------------

EN3 = "CALL   MOTION_EN3, {slot}, M0.0, M0.1, M0.2, M0.3, M0.4, VW0"
SPD = ("CALL   SPD_CTRL, {slot}, {axis}, +10, +10, +1000, +20000, VD{v}, VB{b}, M1.{d}, "
       "M1.7, M1.{r}, VW{s}, VD{c}")


def _ob1(*bodies: str) -> str:
    lines = ["ORGANIZATION_BLOCK MAIN:OB1", "BEGIN"]
    for i, body in enumerate(bodies or ("=      M10.0",), 1):
        lines += [f"Network {i}", "LD     SM0.0", body]
    lines.append("END_ORGANIZATION_BLOCK")
    return "\n".join(lines) + "\n"


def _spd(slot: int, axis: int) -> str:
    """SPD_CTRL for one axis: Dir M1.(axis*2), Run M1.(axis*2+1)."""
    k = 40 * axis
    return SPD.format(slot=slot, axis=axis, v=100 + k, b=104 + k, d=2 * axis,
                      r=2 * axis + 1, s=106 + k, c=108 + k)


def _plant(slot: int = 0, **axis0: object) -> dict:
    return {"module": {str(slot): {"axis": {"0": dict(axis0), "1": {}}}}}


def _plc(plant: dict, *bodies: str, cpu: str = "CPU226", scan_ms: float = 1) -> plcrt.Plc:
    return plcrt.load(_ob1(*bodies), plant=plant, cpu=cpu, scan_ms=scan_ms)


@pytest.mark.parametrize("axis0,bit", [
    ({"rps": [-10, 10]}, 1),                   # .1 RPS: inside the switch
    ({"start": 500, "limit_pos": 500}, 2),     # .2 L+: at the positive limit
    ({"start": -500, "limit_neg": -499}, 3),   # .3 L-: beyond the negative limit
    ({"start": 8000, "z_period": 4000}, 4),    # .4 Z: exactly on a Z mark
    ({"start": 9000, "z_period": 4000, "z_offset": 1000}, 4),
])
def test_input_bits_of_axis_0_on_ib3(axis0: dict, bit: int) -> None:
    plc = _plc(_plant(**axis0))
    plc.scan()
    assert plc["IB3"] == 1 << bit
    assert plc["IB4"] == 0
    assert plc["IB2"] == 0 and plc["IB5"] == 0


def test_inputs_off_outside_the_switch_limits_and_z() -> None:
    plc = _plc(_plant(start=0, rps=[1, 10], limit_neg=-1, limit_pos=1, z_period=4000,
                      z_offset=1))
    plc.scan()
    assert plc["IB3"] == 0


def test_axis_1_inputs_on_ib4() -> None:
    plant = {"module": {"0": {"axis": {"1": {"rps": [0, 0], "limit_pos": 0}}}}}
    plc = _plc(plant)
    plc.scan()
    assert (plc["IB3"], plc["IB4"]) == (0, 0b110)


def test_stf_input_bit_follows_the_plant_event() -> None:
    """STF is scripted in the plant file; it shows on .0 from the next scan."""
    plant = _plant(events=[{"at": 0.0105, "input": "STF", "value": True},
                           {"at": 0.0305, "input": "STF", "value": False}])
    plc = _plc(plant, EN3.format(slot=0))
    seen = []
    for _ in range(40):
        plc.scan()
        seen.append(plc["I3.0"])
    # the scan starting at 11 ms reads the input that changed at 10.5 ms
    assert seen == [0] * 11 + [1] * 20 + [0] * 9


def test_stf_makes_motion_en3_report_status_4() -> None:
    plant = _plant(events=[{"at": 0.005, "input": "STF", "value": True}])
    plc = _plc(plant, EN3.format(slot=0))
    plc.scan(3)
    assert plc["VW0"] == 1
    plc.scan(5)
    assert plc["VW0"] == 4


def test_status_returns_to_1_when_stf_is_released() -> None:
    plant = _plant(events=[{"at": 0.005, "input": "STF", "value": True},
                           {"at": 0.010, "input": "STF", "value": False}])
    plc = _plc(plant, EN3.format(slot=0))
    plc.scan(8)
    assert plc["VW0"] == 4
    plc.scan(5)
    assert plc["VW0"] == 1


def test_output_bits_en_p_d_on_qb2_and_qb3() -> None:
    """.0 En follows SevOn, .2 P is on while pulsing, .3 D is the direction."""
    plc = _plc(_plant(), EN3.format(slot=0), _spd(0, 0), _spd(0, 1))
    plc.scan()
    assert (plc["QB2"], plc["QB3"]) == (0b1000, 0b1000)  # stopped, D left positive
    plc["M1.0"] = 1      # axis 0: Dir positive, Run
    plc["M1.1"] = 1
    plc["M1.2"] = 1      # axis 1: Dir positive, Run
    plc["M1.3"] = 1
    plc.scan(5)
    assert plc["Q2.2"] == 1 and plc["Q3.2"] == 1
    assert plc.axis(0, 1)["speed"] > 0
    plc["M0.1"] = 1      # SevOn0: pulses and direction masked, En on
    plc.scan(2)
    assert plc["QB2"] == 0b0001
    assert plc["Q3.2"] == 1
    plc["M0.1"] = 0
    plc.scan(2)
    assert plc["QB2"] == 0b1100


def test_direction_bit_is_off_for_negative_moves() -> None:
    plc = _plc(_plant(), EN3.format(slot=0), _spd(0, 0))
    plc["M1.1"] = 1      # Run with Dir M1.0 = 0: negative
    plc.scan(5)
    assert plc["QB2"] == 0b0100
    assert plc.axis(0, 0)["speed"] < 0


def test_sev_on_masks_the_motor_but_the_counter_counts() -> None:
    plc = _plc(_plant(), EN3.format(slot=0), _spd(0, 0))
    plc["M1.0"] = 1
    plc["M1.1"] = 1
    plc.scan(50)
    before = plc.axis(0, 0)
    plc["M0.1"] = 1
    plc.scan(50)
    masked = plc.axis(0, 0)
    # masked from the start of the scan whose MOTION_EN3 saw SevOn
    assert masked["mechanical"] == before["mechanical"]
    assert masked["position"] > before["position"] + 900


@pytest.mark.parametrize("scan_ms", [1, 10, 7])
def test_clr_pulse_lasts_200_ms_and_clr_clears_itself(scan_ms: float) -> None:
    """Manual 2.1 / 3.2.1: Clr = 1 gives a pulse of about 200 ms on CLR,
    then the Clr bit goes back to 0 by itself."""
    plc = _plc(_plant(), EN3.format(slot=0), scan_ms=scan_ms)
    plc.scan(3)
    plc["M0.3"] = 1
    t_set = plc.time
    on_times, clr_bit = [], []
    for _ in range(int(400 / scan_ms)):
        plc.scan()
        if plc["Q2.1"]:
            on_times.append(plc.time)  # the output image after this scan
        clr_bit.append((plc.time, plc["M0.3"]))
    assert on_times, "no CLR pulse"
    first, last = on_times[0], on_times[-1]
    assert first == pytest.approx(t_set + scan_ms / 1000)
    # on from the end of the scan that saw Clr until the first scan end at
    # or after 200 ms: 200 ms rounded to whole scans, minus one scan
    length = last - first + scan_ms / 1000
    assert 0.2 - scan_ms / 1000 <= length + 1e-9 <= 0.2 + scan_ms / 1000
    assert len(on_times) == round(length * 1000 / scan_ms)
    assert plc["Q3.1"] == 0
    # Clr stays 1 during the pulse and is cleared by MOTION_EN3 after it
    cleared = next(t for t, v in clr_bit if v == 0)
    assert cleared >= t_set + 0.2
    assert all(v == 1 for t, v in clr_bit if t < t_set + 0.2)
    assert plc["M0.3"] == 0 and plc["Q2.1"] == 0


def test_clr1_pulses_axis_1_only() -> None:
    plc = _plc(_plant(), EN3.format(slot=0))
    plc["M0.4"] = 1
    plc.scan(2)
    assert (plc["Q2.1"], plc["Q3.1"]) == (0, 1)
    plc.run(seconds=0.25)
    assert (plc["Q3.1"], plc["M0.4"]) == (0, 0)


# ---------------------------------------------------------------------------
# Slot placement
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("cpu,slot,ib,qb", [
    ("CPU226", 0, 3, 2),
    ("CPU226", 1, 5, 4),
    ("CPU226", 5, 13, 12),
    ("CPU224", 0, 2, 2),
    ("CPU224XP", 3, 8, 8),
    ("CPU224", 6, 14, 14),
    ("CPU222", 0, 1, 1),
])
def test_slot_placement(cpu: str, slot: int, ib: int, qb: int) -> None:
    """Module n sits after the CPU's own I/O and n earlier 16 DI / 16 DO modules."""
    plant = {"module": {str(slot): {"axis": {"0": {"rps": [0, 0]},
                                             "1": {"limit_neg": 0}}}}}
    plc = _plc(plant, EN3.format(slot=slot), _spd(slot, 0), cpu=cpu)
    plc["M1.1"] = 1
    plc["M1.0"] = 1
    plc.scan()
    assert (plc[f"IB{ib}"], plc[f"IB{ib + 1}"]) == (0b10, 0b1000)
    assert plc[f"QB{qb}"] == 0b1100 and plc[f"QB{qb + 1}"] == 0b1000
    assert plc.module(slot).di == ib and plc.module(slot).do == qb


def test_slot_that_does_not_fit_the_process_image() -> None:
    """A CPU 226 has IB0..IB15: slot 6 would need IB15-IB16."""
    with pytest.raises(plcrt.PlcConfigError) as info:
        _plc({"module": {"6": {}}})
    msg = str(info.value)
    assert "slot 6" in msg and "IB15" in msg and "CPU226" in msg


def test_two_modules_side_by_side() -> None:
    plant = {"module": {"0": {"axis": {"0": {"rps": [0, 0]}}},
                        "1": {"axis": {"1": {"limit_pos": 0}}}}}
    plc = _plc(plant)
    plc.scan()
    assert [plc[f"IB{i}"] for i in range(3, 7)] == [0b10, 0, 0, 0b100]
