"""A custom Modbus map (plcrt.net.modbus.load_map): a plant simulator's
client writes the PLC's inputs and reads its outputs, as Factory I/O's
Modbus TCP client driver does (docs/network.md, "A custom map")."""

from __future__ import annotations

import time

import pytest

pytest.importorskip("pymodbus")
from pymodbus.client import ModbusTcpClient  # noqa: E402

import plcrt  # noqa: E402
from plcrt.errors import PlcConfigError  # noqa: E402
from plcrt.net.modbus import load_map  # noqa: E402

from .modbus_net_helpers import REACT, wait_for  # noqa: E402

#: sensors: coils -> I, analog sensors: holding registers -> AIW;
#: actuators: discrete inputs <- Q, input registers <- VW
PLANT_MAP = """
[[coils]]
start = 0
count = 16
to = "I0.0"
[[discrete_inputs]]
start = 0
count = 16
to = "Q0.0"
[[holding_registers]]
start = 0
count = 2
to = "AIW0"
[[holding_registers]]
start = 2
count = 2
to = "VW100"
[[holding_registers]]
start = 100
count = 4
to = "MW0"
[[input_registers]]
start = 0
count = 4
to = "VW0"
"""


def ok(r):
    assert not r.isError(), r
    return r


def test_a_plant_client_writes_inputs_and_reads_outputs(tmp_path):
    path = tmp_path / "plant_map.toml"
    path.write_text(PLANT_MAP)
    plc = plcrt.load(REACT)
    with plcrt.serve(plc, modbus=0, modbus_map=str(path)) as s, \
            ModbusTcpClient("127.0.0.1", port=s.port("modbus"), timeout=5) as c:
        ok(c.write_coil(0, True))                       # the sensor I0.0
        # the image and the physical input (PI), so the next scan keeps it
        assert s.call(lambda p: (p.read("I0.0"), p.mem.areas["PI"][0] & 1)) == (1, 1)
        wait_for(lambda: ok(c.read_discrete_inputs(0, count=16)).bits[1],
                 what="Q0.1 follows the written I0.0")
        time.sleep(0.1)                                 # scans read I := PI: it stays
        assert s.call(lambda p: p.read("I0.0")) == 1
        ok(c.write_registers(0, [100, 0, 5, 6]))        # AIW0, AIW2, VW100, VW102
        assert s.call(lambda p: (p.read("AIW0"), p.read("VW100"), p.read("VW102"))) \
            == (100, 5, 6)
        wait_for(lambda: ok(c.read_input_registers(2, count=1)).registers == [101],
                 what="VW4 = AIW0 + 1")
        # one request over two adjacent ranges; a gap between ranges is exception 2
        assert ok(c.read_holding_registers(0, count=4)).registers == [100, 0, 5, 6]
        r = c.read_holding_registers(3, count=2)
        assert r.isError() and r.exception_code == 2
        ok(c.write_register(101, 9))
        assert s.call(lambda p: p.read("MW2")) == 9
        # a custom map has no byte rule for function 15
        ok(c.write_coils(3, [True, True]))
        assert s.call(lambda p: p.read("IB0")) == 0b11001
        r = c.read_coils(16, count=1)
        assert r.isError() and r.exception_code == 2


def test_a_map_as_a_dict_and_the_guard_on_its_targets():
    plc = plcrt.load(REACT)
    amap = {"coils": [{"start": 0, "count": 8, "to": "I0.0"}],
            "holding_registers": [{"start": 0, "count": 8, "to": "VW0"}]}
    with plcrt.serve(plc, modbus=0, modbus_map=amap, allow_writes="I0.0-I0.7") as s, \
            ModbusTcpClient("127.0.0.1", port=s.port("modbus"), timeout=5) as c:
        ok(c.write_coil(2, True))
        r = c.write_register(0, 1)                      # VW0: not in the allow-list
        assert r.isError() and r.exception_code == 2
        assert s.call(lambda p: (p.read("I0.2"), p.read("VW0"))) == (1, 0)


@pytest.mark.parametrize("bad, match", [
    ({"coil": []}, "unknown key"),
    ({"coils": [{"start": 0, "count": 8}]}, "start, count and to"),
    ({"coils": [{"start": 0, "count": 8, "to": "Q0.8"}]}, "not a bit address"),
    ({"coils": [{"start": 0, "count": 8, "to": "VW0"}]}, "not a bit address"),
    ({"holding_registers": [{"start": 0, "count": 8, "to": "V0.0"}]}, "not a word address"),
    ({"holding_registers": [{"start": 0, "count": 2, "to": "VW10238"}]}, "past the end"),
    ({"coils": [{"start": 0, "count": 129, "to": "Q0.0"}]}, "past the end"),
    ({"coils": [{"start": 0, "count": 8, "to": "Q0.0"},
                {"start": 7, "count": 8, "to": "M0.0"}]}, "overlap"),
    ({"coils": [{"start": -1, "count": 8, "to": "Q0.0"}]}, "0..65535"),
    ({"coils": [{"start": 65535, "count": 2, "to": "Q0.0"}]}, "1..1"),
    ({"coils": [{"start": 0, "count": True, "to": "Q0.0"}]}, "whole number"),
    ({"coils": "Q0.0"}, "list of tables"),
    ({"coils": [{"start": i, "count": 1, "to": "M0.0"} for i in range(257)]}, "at most"),
    (42, "TOML file or a dict"),
])
def test_bad_maps_are_config_errors(bad, match):
    plc = plcrt.load(REACT)
    with pytest.raises(PlcConfigError, match=match):
        load_map(bad, plc.mem.areas)


def test_a_map_file_that_cannot_be_read_is_a_config_error(tmp_path):
    with pytest.raises(PlcConfigError, match="cannot read"):
        load_map(str(tmp_path / "missing.toml"))
    bad = tmp_path / "bad.toml"
    bad.write_text("[[coils]\n")
    with pytest.raises(PlcConfigError, match="bad.toml"):
        load_map(str(bad))
