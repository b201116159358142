"""PDO mapping: entries, capacity, the HCFA default maps, the dynamic mapping
procedure A–H (HCFA §6.7.4) with its abort codes, and process data images."""

from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from plcrt.devices.cia402.esm import Esm, EsmState
from plcrt.devices.cia402.pdo import (
    DEFAULT_ASSIGN, DEFAULT_MAPS, MAX_BYTES, MAX_ENTRIES, RX_MAPS, TX_MAPS, MapEntry,
    PdoConfig, layout, pack, unpack,
)
from plcrt.errors import PlcError

#: The objects the default maps use (HCFA §3.2 sizes and PDO directions), a
#: vendor 64-bit test object and a non-mappable one.
OBJECTS: dict[tuple[int, int], tuple[int, str]] = {
    (0x6040, 0): (16, "rx"), (0x607A, 0): (32, "rx"), (0x60B8, 0): (16, "rx"),
    (0x6081, 0): (32, "rx"), (0x6083, 0): (32, "rx"), (0x6084, 0): (32, "rx"),
    (0x6060, 0): (8, "rx"), (0x60FF, 0): (32, "rx"), (0x6098, 0): (8, "rx"),
    (0x6099, 1): (32, "rx"), (0x6099, 2): (32, "rx"), (0x609A, 0): (32, "rx"),
    (0x607C, 0): (32, "rx"),
    (0x6041, 0): (16, "tx"), (0x603F, 0): (16, "tx"), (0x6064, 0): (32, "tx"),
    (0x606C, 0): (32, "tx"), (0x6061, 0): (8, "tx"), (0x60B9, 0): (16, "tx"),
    (0x60BA, 0): (32, "tx"), (0x60F4, 0): (32, "tx"),
    (0x1000, 0): (32, ""), (0x2100, 1): (64, "rx"),
}


def make(objects=OBJECTS, state: EsmState = EsmState.PREOP):
    box = {"esm": None}
    cfg = PdoConfig(lambda i, s: objects.get((i, s)), lambda: box["esm"].state)
    esm = Esm(cfg.activate)
    box["esm"] = esm
    for s in (EsmState.PREOP, EsmState.SAFEOP, EsmState.OP):
        if esm.state is state:
            break
        assert esm.request(s).accepted, esm.al_code
    return cfg, esm


def e(index: int, sub: int, bits: int) -> int:
    return index << 16 | sub << 8 | bits


# ---------------------------------------------------------------- data

def test_map_entry_parse_and_raw():
    entry = MapEntry.parse(0x60990120)
    assert (entry.index, entry.sub, entry.bits) == (0x6099, 1, 32)
    assert entry.raw == 0x60990120 and str(entry) == "6099h:01 (32 bits)"
    with pytest.raises(PlcError, match="UDINT"):
        MapEntry.parse(1 << 32)


def test_default_maps_have_the_manual_counts_and_fit():
    """HCFA §8.2 counts 3, 6, 5, 7 / 7, 0; each within 8 entries and 32 bytes
    (§6.7.2); only 1600h and 1A00h are assigned."""
    assert {k: len(v) for k, v in DEFAULT_MAPS.items()} == {
        0x1600: 3, 0x1601: 6, 0x1602: 5, 0x1603: 7, 0x1A00: 7, 0x1A01: 0}
    for index, rows in DEFAULT_MAPS.items():
        entries = [MapEntry.parse(r) for r in rows]
        assert len(entries) <= MAX_ENTRIES and sum(x.bits for x in entries) <= MAX_BYTES * 8
        side = "rx" if index in RX_MAPS else "tx"
        assert all(OBJECTS[(x.index, x.sub)] == (x.bits, side) for x in entries)
    assert DEFAULT_ASSIGN == {0x1C12: (0x1600,), 0x1C13: (0x1A00,)}
    assert RX_MAPS == (0x1600, 0x1601, 0x1602, 0x1603) and TX_MAPS == (0x1A00, 0x1A01)


def test_default_active_mapping_and_reads():
    cfg, _ = make()
    assert [str(x) for x in cfg.active_rx] == ["6040h:00 (16 bits)", "607Ah:00 (32 bits)",
                                               "60B8h:00 (16 bits)"]
    assert len(cfg.active_tx) == 7
    assert cfg.read(0x1600, 0) == 3 and cfg.read(0x1600, 2) == 0x607A0020
    assert cfg.read(0x1C12, 0) == 1 and cfg.read(0x1C12, 1) == 0x1600
    assert cfg.read(0x1A01, 0) == 0
    with pytest.raises(PlcError, match="does not exist"):
        cfg.read(0x1604, 0)


# ---------------------------------------------------------------- procedure A–H

def procedure(cfg: PdoConfig) -> list[int]:
    """Steps B–G for a PP RxPDO in 1601h and a TxPDO with 60F4h in 1A01h."""
    steps = [
        (0x1C12, 0, 0), (0x1C13, 0, 0),                                       # B
        (0x1601, 0, 0), (0x1A01, 0, 0),                                       # C
        (0x1601, 1, e(0x6040, 0, 16)), (0x1601, 2, e(0x607A, 0, 32)),         # D
        (0x1601, 3, e(0x6081, 0, 32)),
        (0x1A01, 1, e(0x6041, 0, 16)), (0x1A01, 2, e(0x60F4, 0, 32)),
        (0x1601, 0, 3), (0x1A01, 0, 2),                                       # E
        (0x1C12, 1, 0x1601), (0x1C13, 1, 0x1A00), (0x1C13, 2, 0x1A01),        # F
        (0x1C12, 0, 1), (0x1C13, 0, 2),                                       # G
    ]
    return [cfg.write(*s).abort for s in steps]


def test_procedure_in_order_takes_effect_at_safeop():
    """Steps A–H in the manual's order: every write succeeds, and the new
    mapping is active only after PRE-OP -> SAFE-OP."""
    cfg, esm = make()                                                         # A
    assert procedure(cfg) == [0] * 16
    assert len(cfg.active_rx) == 3 and cfg.active_rx[2].index == 0x60B8       # not yet
    assert esm.request(EsmState.SAFEOP).accepted                              # H
    assert [x.index for x in cfg.active_rx] == [0x6040, 0x607A, 0x6081]
    assert [x.index for x in cfg.active_tx][-2:] == [0x6041, 0x60F4]
    assert len(cfg.active_tx) == 9


@pytest.mark.parametrize("state", [EsmState.INIT, EsmState.SAFEOP, EsmState.OP])
def test_step_a_skipped_is_0x08000022(state):
    cfg, _ = make(state=state)
    r = cfg.write(0x1C12, 0, 0)
    assert r.abort == 0x08000022 and state.name in r.explanation and "step A" in r.explanation


def test_step_b_skipped_changing_an_assigned_map_is_0x06010003():
    cfg, _ = make()
    r = cfg.write(0x1600, 0, 0)
    assert r.abort == 0x06010003 and "step B" in r.explanation


def test_step_c_skipped_writing_entries_of_a_valid_map_is_0x06010003():
    cfg, _ = make()
    cfg.write(0x1C12, 0, 0)
    r = cfg.write(0x1601, 1, e(0x6040, 0, 16))
    assert r.abort == 0x06010003 and "1601:00 = 6" in r.explanation


@pytest.mark.parametrize("entry,code,text", [
    (e(0x6041, 0, 16), 0x06040041, "not RXPDO-mappable"),
    (e(0x1000, 0, 32), 0x06040041, "mappable: no"),
    (e(0x6FFF, 0, 16), 0x06020000, "not in the object dictionary"),
    (e(0x6099, 3, 32), 0x06020000, "6099h:03"),
    (e(0x6040, 0, 32), 0x06040043, "16 bits, the entry says 32"),
])
def test_step_d_bad_entries(entry, code, text):
    cfg, _ = make()
    cfg.write(0x1C12, 0, 0)
    cfg.write(0x1601, 0, 0)
    r = cfg.write(0x1601, 1, entry)
    assert r.abort == code and text in r.explanation
    assert cfg.read(0x1601, 1) == DEFAULT_MAPS[0x1601][0]


def test_step_d_txpdo_refuses_rx_objects():
    cfg, _ = make()
    cfg.write(0x1C13, 0, 0)
    cfg.write(0x1A00, 0, 0)
    assert cfg.write(0x1A00, 1, e(0x6040, 0, 16)).abort == 0x06040041


def test_padding_entries_are_accepted():
    cfg, _ = make()
    cfg.write(0x1C12, 0, 0)
    cfg.write(0x1601, 0, 0)
    assert cfg.write(0x1601, 2, e(0, 0, 16)).ok


@pytest.mark.parametrize("count", [9, 255])
def test_step_e_more_than_8_entries_is_0x06040042(count):
    cfg, _ = make()
    cfg.write(0x1C12, 0, 0)
    cfg.write(0x1601, 0, 0)
    assert cfg.write(0x1601, 0, count).abort == 0x06040042


def test_step_e_more_than_32_bytes_is_0x06040042():
    cfg, _ = make()
    cfg.write(0x1C12, 0, 0)
    cfg.write(0x1601, 0, 0)
    for sub in range(1, 6):
        assert cfg.write(0x1601, sub, e(0x2100, 1, 64)).ok
    r = cfg.write(0x1601, 0, 5)
    assert r.abort == 0x06040042 and "40 bytes" in r.explanation
    assert cfg.write(0x1601, 0, 4).ok


def test_step_e_before_d_is_0x06040043():
    """A count over entries never written (the cleared 1A01h)."""
    cfg, _ = make()
    cfg.write(0x1C13, 0, 0)
    r = cfg.write(0x1A01, 0, 2)
    assert r.abort == 0x06040043 and "step D before E" in r.explanation


def test_step_f_before_b_is_0x06010003():
    cfg, _ = make()
    assert cfg.write(0x1C12, 1, 0x1601).abort == 0x06010003


@pytest.mark.parametrize("index,value", [(0x1C12, 0x1A00), (0x1C13, 0x1600), (0x1C12, 0x1604)])
def test_step_f_wrong_map_index_is_0x06090030(index, value):
    cfg, _ = make()
    cfg.write(index, 0, 0)
    assert cfg.write(index, 1, value).abort == 0x06090030


def test_step_g_too_many_or_before_f_or_twice():
    cfg, _ = make()
    cfg.write(0x1C12, 0, 0)
    assert cfg.write(0x1C12, 0, 5).abort == 0x06090031
    assert cfg.write(0x1C12, 0, 2).abort == 0x06040043             # 1C12:02 never written
    cfg.write(0x1C12, 2, 0x1600)
    assert cfg.write(0x1C12, 0, 2).abort == 0x06040043             # 1600h twice
    cfg.write(0x1C12, 2, 0x1602)
    assert cfg.write(0x1C12, 0, 2).ok


@pytest.mark.parametrize("index,sub,code", [(0x1604, 0, 0x06020000), (0x1600, 9, 0x06090011),
                                            (0x1C13, 3, 0x06090011), (0x1C12, 5, 0x06090011)])
def test_unknown_mapping_object_or_subindex(index, sub, code):
    cfg, _ = make()
    assert cfg.write(index, sub, 0).abort == code


@pytest.mark.parametrize("missing,side,code", [((0x60B8, 0), "outputs", 0x001D),
                                               ((0x60BA, 0), "inputs", 0x001E)])
def test_step_h_with_a_mapping_the_dictionary_cannot_serve(missing, side, code):
    """At PRE-OP -> SAFE-OP the assigned maps are checked against the object
    dictionary: a bad one keeps PRE-OP with AL 0x001D / 0x001E and alarm 35."""
    objects = {k: v for k, v in OBJECTS.items() if k != missing}
    cfg, esm = make(objects)
    r = esm.request(EsmState.SAFEOP)
    assert not r.accepted and esm.state is EsmState.PREOP and esm.al_code == code
    assert r.fault is not None and r.fault[0] == 35
    assert f"{missing[0]:04X}h" in r.explanation


def test_empty_assignment_is_valid():
    cfg, esm = make()
    cfg.write(0x1C12, 0, 0)
    assert esm.request(EsmState.SAFEOP).accepted and cfg.active_rx == ()


# ---------------------------------------------------------------- images

def test_pack_default_rxpdo_is_little_endian():
    """1600h: 6040h (16) | 607Ah (32) | 60B8h (16) = 8 bytes, CoE little-endian."""
    cfg, _ = make()
    data = pack(cfg.active_rx, {(0x6040, 0): 0x000F, (0x607A, 0): -2, (0x60B8, 0): 0x0102})
    assert data == bytes.fromhex("0f00" "feffffff" "0201")
    assert unpack(cfg.active_rx, data, signed=frozenset({(0x607A, 0)})) == {
        (0x6040, 0): 0x000F, (0x607A, 0): -2, (0x60B8, 0): 0x0102}


def test_layout_offsets_and_padding():
    entries = [MapEntry(0x6040, 0, 16), MapEntry(0, 0, 8), MapEntry(0x6060, 0, 8)]
    assert [o for _, o in layout(entries)] == [0, 16, 24]
    data = pack(entries, {(0x6040, 0): 1, (0x6060, 0): 6})
    assert data == bytes([1, 0, 0, 6])
    assert unpack(entries, data) == {(0x6040, 0): 1, (0x6060, 0): 6}


def test_pack_and_unpack_errors():
    entries = [MapEntry(0x6040, 0, 16)]
    with pytest.raises(PlcError, match="no value"):
        pack(entries, {})
    with pytest.raises(PlcError, match="does not fit"):
        pack(entries, {(0x6040, 0): 0x10000})
    with pytest.raises(PlcError, match="needs 2"):
        unpack(entries, b"\x00")


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.integers(0x6000, 0x6FFF), st.sampled_from([8, 16, 32]),
                          st.booleans(), st.data()), min_size=1, max_size=8, unique_by=lambda x: x[0]))
def test_pack_unpack_round_trip(rows):
    """Any mapping of 8/16/32-bit objects: unpack(pack(v)) == v, signed or not."""
    entries, values, signed = [], {}, set()
    for index, bits, is_signed, data in rows:
        entries.append(MapEntry(index, 0, bits))
        if is_signed:
            signed.add((index, 0))
            v = data.draw(st.integers(-(1 << (bits - 1)), (1 << (bits - 1)) - 1))
        else:
            v = data.draw(st.integers(0, (1 << bits) - 1))
        values[(index, 0)] = v
    image = pack(entries, values)
    assert len(image) == sum(b for _, b, _, _ in rows) // 8
    assert unpack(entries, image, frozenset(signed)) == values


@pytest.mark.parametrize("index,sub,value", [(0x1600, 0, -1), (0x1600, 0, 256),
                                             (0x1600, 1, 1 << 32), (0x1C12, 1, 0x10000)])
def test_values_outside_the_object_type_are_0x06090030(index, sub, value):
    cfg, _ = make()
    assert cfg.write(index, sub, value).abort == 0x06090030


# -- a CANopen model: no assignment objects, 8-byte PDOs (CiA 301) ----------------

from plcrt.devices.cia402.od import SdoAbort  # noqa: E402


def _kinco_preop():
    from plcrt.devices.cia402.drive import Drive
    from plcrt.devices.cia402.esm import EsmState
    d = Drive("kinco-servo")
    d.request_esm(EsmState.PREOP)
    return d


def test_a_canopen_model_remaps_without_assignment_objects():
    """Kinco: no 1C12h/1C13h, so a map is never locked by an assignment:
    :00 := 0, the entries, :00 := n, as CiA 301 has it; the new map is in
    use after the next start (PRE-OP -> SAFE-OP -> OP)."""
    from plcrt.devices.cia402.esm import EsmState
    d = _kinco_preop()
    d.write(0x1600, 0, 0)
    d.write(0x1600, 1, 0x60400010)
    d.write(0x1600, 2, 0x60FF0020)
    d.write(0x1600, 0, 2)
    assert d.read(0x1600, 0) == 2 and d.read(0x1600, 2) == 0x60FF0020
    d.request_esm(EsmState.SAFEOP)
    assert [e.index for e in d.pdo.active_rx][:2] == [0x6040, 0x60FF]


def test_a_canopen_pdo_holds_eight_bytes():
    """CiA 301: a CAN frame carries 8 bytes; 6040h + 607Ah + 60FFh (10) is
    refused with 0x06040042, the model's own rule named."""
    d = _kinco_preop()
    d.write(0x1600, 0, 0)
    for k, raw in enumerate((0x60400010, 0x607A0020, 0x60FF0020), 1):
        d.write(0x1600, k, raw)
    with pytest.raises(SdoAbort) as e:
        d.write(0x1600, 0, 3)
    assert e.value.code == 0x06040042 and "more than 8" in e.value.message
    assert "CiA 301" in e.value.message


def test_a_canopen_model_has_no_1c12():
    d = _kinco_preop()
    with pytest.raises(SdoAbort) as e:
        d.write(0x1C12, 0, 0)
    assert e.value.code == 0x06020000
    d.write(0x1A03, 0, 0)           # its fourth TxPDO map is a mapping object too
    d.write(0x1A03, 1, 0x60640020)
    d.write(0x1A03, 0, 1)
    assert d.read(0x1A03, 1) == 0x60640020
