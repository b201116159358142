"""The Modbus request PDUs on their own (plcrt.net.modbus.pdu), fuzzed:
whatever bytes a client sends, parsing gives a request or the exception
01 / 03, executing it on the library's map gives a well-formed response or
02 / 03, and nothing else is raised; a failed request writes nothing."""

from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

import plcrt
from plcrt.devices.modbus.rtu import ModbusException
from plcrt.net.modbus.addrmap import DEFAULTS, library_map
from plcrt.net.modbus.pdu import FUNCTIONS, Refused, execute, parse
from plcrt.net.options import WriteGuard, parse_ranges

from .modbus_net_helpers import REACT

PLC = plcrt.load(REACT)
MAP = library_map(PLC.mem.areas, DEFAULTS)
OPEN = WriteGuard()


def _request(fn: int, start: int, count: int, body: bytes) -> bytes:
    return bytes((fn,)) + start.to_bytes(2, "big") + count.to_bytes(2, "big") + body


requests = st.one_of(
    st.binary(max_size=260),
    st.builds(_request, st.sampled_from(sorted(FUNCTIONS)), st.integers(0, 1100),
              st.integers(0, 130), st.binary(max_size=250)),
    st.builds(lambda fn, start, vals: _request(fn, start, len(vals), bytes((2 * len(vals),))
                                               + b"".join(v.to_bytes(2, "big") for v in vals)),
              st.just(16), st.integers(0, 1005), st.lists(st.integers(0, 0xFFFF), max_size=125)),
)


@settings(max_examples=400, deadline=None)
@given(requests)
def test_any_pdu_is_a_request_or_a_library_exception(pdu):
    before = {a: bytes(PLC.mem.areas[a]) for a in ("Q", "I", "PI", "V", "AI")}
    try:
        req = parse(pdu)
    except ModbusException as e:
        assert e.code == (1 if pdu and pdu[0] not in FUNCTIONS else 3)
        return
    try:
        out = execute(PLC.mem.areas, MAP, req, OPEN, True)
    except ModbusException as e:
        assert e.code in (2, 3)
        assert all(bytes(PLC.mem.areas[a]) == b for a, b in before.items())
        return
    assert out[0] == req.fn
    if req.values is None:
        n = (req.count + 7) // 8 if req.bits else 2 * req.count
        assert out[1] == n and len(out) == 2 + n
    else:
        assert len(out) == 5 and out[1:3] == pdu[1:3]


@pytest.mark.parametrize("pdu, code", [
    (b"", 3), (b"\x07", 1), (b"\x03\x00\x00\x00", 3), (b"\x03\x00\x00\x00\x79", 3),
    (b"\x10\x00\x00\x00\x01\x02\x00", 3), (b"\x0f\x00\x00\x00\x08\x02\xff\x00", 3),
    (b"\x05\x00\x00\x00\x01", 3),
])
def test_parse_refuses_with_the_library_codes(pdu, code):
    with pytest.raises(ModbusException) as e:
        parse(pdu)
    assert e.value.code == code


def test_a_refused_write_is_exception_2_and_writes_nothing():
    guard = WriteGuard(allow=parse_ranges("VB0-VB3"))
    req = parse(_request(16, 1, 2, b"\x04\x00\x01\x00\x02"))      # VB2 .. VB5
    before = bytes(PLC.mem.areas["V"][:8])
    with pytest.raises(Refused) as e:
        execute(PLC.mem.areas, MAP, req, guard, True)
    assert e.value.code == 2 and "V bytes 2..5" in e.value.what
    assert bytes(PLC.mem.areas["V"][:8]) == before
    req = parse(_request(16, 0, 2, b"\x04\x00\x01\x00\x02"))      # VB0 .. VB3: allowed
    execute(PLC.mem.areas, MAP, req, guard, True)
    assert bytes(PLC.mem.areas["V"][:4]) == b"\x00\x01\x00\x02"
