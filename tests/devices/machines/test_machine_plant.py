"""The plant file's [machine.NAME] tables: defaults, remapping so that a
program written for other addresses runs unchanged, and every bad key or
address a PlcConfigError naming it (docs/machines.md)."""

from __future__ import annotations

import re

import pytest

import plcrt
from plcrt import PlcConfigError

from machine_helpers import EXAMPLES, MANUAL


def test_defaults_are_documented_addresses() -> None:
    plc = plcrt.load(MANUAL, plant="[machine.conveyor]\n")
    assert plc.machine("conveyor").wiring() == {
        "eye_entry": "I0.0", "eye_tall": "I0.1", "eye_gate": "I0.2", "eye_exit": "I0.3",
        "start": "I0.4", "stop": "I0.5", "motor": "Q0.0", "gate": "Q0.1", "divert": "Q0.2"}


def test_a_program_for_other_addresses_runs_with_a_mapped_plant() -> None:
    # the example moved to I1.x / Q1.x, as another author might have wired it
    text = (EXAMPLES / "conveyor.awl").read_text()
    moved = re.sub(r"\b([IQ])0\.(\d)", r"\g<1>1.\2", text)
    assert moved != text
    plant = """
[machine.belt]
kind = "conveyor"
pattern = "STTSS"
outputs = { motor = "Q1.0", gate = "Q1.1", divert = "Q1.2" }
[machine.belt.inputs]
eye_entry = "I1.0"
eye_tall = "I1.1"
eye_gate = "I1.2"
eye_exit = "I1.3"
start = "I1.4"
stop = "I1.5"
"""
    results = []
    for program, plant_text in ((text, '[machine.belt]\nkind = "conveyor"\npattern = "STTSS"\n'),
                                (moved, plant)):
        plc = plcrt.load(program, plant=plant_text)
        m = plc.machine("belt")
        m.press("start")
        plc.run(seconds=40)
        results.append((m.state()["bins"], m.edges()))
    assert results[0] == results[1]
    assert results[0][0]["diverted_tall"] > 0


def test_an_unwired_signal_drives_nothing() -> None:
    plc = plcrt.load(MANUAL, plant={"machine": {"tank": {"inputs": {"flow": False}}}})
    m = plc.machine("tank")
    assert m.wiring()["flow"] == ""
    plc["VB0"] = 1
    plc.run(seconds=1)
    assert plc["AIW2"] == 0 and m.state()["inputs"]["flow"] == 32000


def test_two_machines_in_one_plant() -> None:
    plc = plcrt.load(MANUAL, plant="""
[machine.tank]
inputs = { low = "I1.0", high = "I1.1", start = "I1.2", stop = "I1.3", level = "AIW4", flow = false }
outputs = { inlet = "Q1.0", outlet = "Q1.1", pump = "Q1.2" }
[machine.garage]
""")
    assert [plc.machine(n).kind for n in ("tank", "garage")] == ["tank", "garage"]
    with pytest.raises(plcrt.PlcAddressError, match="no machine 'lift'.*tank, garage"):
        plc.machine("lift")


@pytest.mark.parametrize("plant, message", [
    ("[machine.conveyor]\nspeeed = 3\n", r"machine\.conveyor: unknown key\(s\) speeed"),
    ("[machine.conveyor]\ninputs = { eye = \"I0.0\" }\n",
     r"machine\.conveyor\.inputs: unknown signal\(s\) eye"),
    ("[machine.conveyor]\ninputs = { eye_entry = \"I0.8\" }\n",
     r"machine\.conveyor\.inputs\.eye_entry must be an input bit"),
    ("[machine.conveyor]\ninputs = { eye_entry = \"Q0.0\" }\n",
     r"machine\.conveyor\.inputs\.eye_entry must be an input bit"),
    ("[machine.conveyor]\noutputs = { motor = \"I0.0\" }\n",
     r"machine\.conveyor\.outputs\.motor must be an output bit"),
    ("[machine.conveyor]\ninputs = { eye_entry = \"AIW0\" }\n",
     r"machine\.conveyor\.inputs\.eye_entry must be an input bit In\.m, got AIW0"),
    ("[machine.tank]\ninputs = { level = \"AIW3\" }\n",
     r"machine\.tank\.inputs\.level must be"),
    ("[machine.tank]\ninputs = { level = \"I1.0\" }\n",
     r"machine\.tank\.inputs\.level must be an analog word"),
    ("[machine.conveyor]\n[machine.garage]\n",
     r"machine\.garage\.inputs\.limit_open: I0\.0 is already driven by "
     r"machine\.conveyor\.inputs\.eye_entry"),
    ("[cpu]\nwire = { \"I0.1\" = \"Q0.5\" }\n[machine.conveyor]\n",
     r"machine\.conveyor\.inputs\.eye_tall: I0\.1 is already driven by cpu\.wire"),
    ("[machine.lift]\n", r"machine\.lift\.kind: unknown machine 'lift'"),
    ("[machine.Belt]\nkind = \"conveyor\"\n", r"machine\.Belt: a machine's name"),
    ("[machine.conveyor]\nspeed = 0\n", r"machine\.conveyor\.speed must be a whole number"),
    ("[machine.conveyor]\nspeed = 2.5\n", r"machine\.conveyor\.speed must be a whole number"),
    ("[machine.conveyor]\npattern = \"TX\"\n", r"machine\.conveyor\.pattern must be text"),
    ("[machine.conveyor]\ngate_at = 1600\n", r"gate_at \(1600\) must be below divert_at"),
    ("[machine.conveyor]\nfaults = [\"melt\"]\n",
     r"machine\.conveyor\.faults\[0\]: unknown fault 'melt'"),
    ("[machine.tank]\nlow = 95000\n", r"machine\.tank: the switches need"),
    ("[machine.garage]\nstart = 9999\n", r"machine\.garage\.start"),
    ("machine = 3\n", r"\[machine\] must be a table"),
])
def test_bad_machine_tables_name_their_key(plant: str, message: str) -> None:
    with pytest.raises(PlcConfigError, match=message):
        plcrt.load(MANUAL, plant=plant)


def test_an_address_outside_the_cpus_image_is_refused() -> None:
    # a CPU 221 has no analog inputs
    with pytest.raises(PlcConfigError, match=r"machine\.tank: level = AIW0 is outside"):
        plcrt.load(MANUAL, cpu="CPU 221", plant={"machine": {"tank": {}}})
