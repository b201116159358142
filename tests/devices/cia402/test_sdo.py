"""SDO semantics of the drive store: every abort code of digest §6.3 that the
object dictionary data decides, for both drive models, plus the power-up and
stopped-only parameter rules, the PDO mapping procedure (HCFA §6.7.4) and the
write hooks."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plcrt.devices.cia402.od import ObjectDictionary, SdoAbort
from plcrt.devices.cia402.store import Store, Write
from plcrt.errors import PlcConfigError, PlcError


def u(value: int, size: int) -> bytes:
    return value.to_bytes(size, "little")


def i(value: int, size: int) -> bytes:
    return value.to_bytes(size, "little", signed=True)


@pytest.fixture(scope="module", params=["hcfa-am0520b", "kinco-servo"])
def od(request: pytest.FixtureRequest) -> ObjectDictionary:
    return ObjectDictionary.load(request.param)


# (case, model, preparation writes, operation, expected abort code)
# op: ("r", index, sub) or ("w", index, sub, data, {state/moving})
ABORTS = [
    ("unknown object, read", "*", [], ("r", 0x6007, 0), 0x06020000),
    ("unknown object, write", "*", [], ("w", 0x5FFF, 0, u(1, 2), {}), 0x06020000),
    ("unknown subindex (HCFA has 6099h:01/02 only)", "hcfa-am0520b", [], ("r", 0x6099, 3), 0x06090011),
    ("unknown subindex (Kinco has 6099h:01-06)", "kinco-servo", [], ("r", 0x6099, 7), 0x06090011),
    ("subindex of a single-entry object", "*", [], ("w", 0x6040, 1, u(6, 2), {}), 0x06090011),
    ("write to read-only statusword", "*", [], ("w", 0x6041, 0, u(0, 2), {}), 0x06010002),
    ("write to read-only 6502h", "*", [], ("w", 0x6502, 0, u(0, 4), {}), 0x06010002),
    ("write to read-only P18.06 bus voltage", "hcfa-am0520b", [], ("w", 0x2012, 6, u(240, 2), {}),
     0x06010002),
    ("controlword too long", "*", [], ("w", 0x6040, 0, u(6, 4), {}), 0x06070012),
    ("controlword too short", "*", [], ("w", 0x6040, 0, u(6, 1), {}), 0x06070013),
    ("target position too short", "*", [], ("w", 0x607A, 0, u(1, 2), {}), 0x06070013),
    ("mode of operation too long", "*", [], ("w", 0x6060, 0, u(1, 2), {}), 0x06070012),
    ("mode 9 (CSV) is not in 6502h", "*", [], ("w", 0x6060, 0, i(9, 1), {}), 0x06090030),
    ("mode 4 (torque) is not in 6502h", "*", [], ("w", 0x6060, 0, i(4, 1), {}), 0x06090030),
    ("P00.02 microsteps above 51200", "hcfa-am0520b", [], ("w", 0x2000, 2, u(51201, 2), {}), 0x06090031),
    ("P00.02 microsteps below 200", "hcfa-am0520b", [], ("w", 0x2000, 2, u(199, 2), {}), 0x06090032),
    ("6098h above 100", "hcfa-am0520b", [], ("w", 0x6098, 0, i(101, 1), {}), 0x06090031),
    ("6098h below 0", "hcfa-am0520b", [], ("w", 0x6098, 0, i(-17, 1), {}), 0x06090032),
    ("605Ah above 8", "*", [], ("w", 0x605A, 0, i(9, 2), {}), 0x06090031),
    ("6099h:05 offset mode above 1", "kinco-servo", [], ("w", 0x6099, 5, u(2, 1), {}), 0x06090031),
    ("6098h method 15 (reserved)", "kinco-servo", [], ("w", 0x6098, 0, i(15, 1), {}), 0x06090030),
    ("6098h method -19", "kinco-servo", [], ("w", 0x6098, 0, i(-19, 1), {}), 0x06090030),
    ("mapping count in SAFEOP", "*", [], ("w", 0x1600, 0, u(0, 1), {"state": "SAFEOP"}), 0x08000022),
    ("mapping entry in OP", "*", [], ("w", 0x1A00, 1, u(0, 4), {"state": "OP"}), 0x08000022),
    ("mapping in INIT", "*", [], ("w", 0x1600, 0, u(0, 1), {"state": "INIT"}), 0x08000022),
    ("assignment in SAFEOP", "hcfa-am0520b", [], ("w", 0x1C12, 0, u(0, 1), {"state": "SAFEOP"}),
     0x08000022),
    ("stopped-only P03.07 while moving", "hcfa-am0520b", [], ("w", 0x2003, 7, u(100, 2), {"moving": True}),
     0x08000022),
    ("stopped-only P02.01 while moving", "hcfa-am0520b", [], ("w", 0x2002, 1, u(1, 2), {"moving": True}),
     0x08000022),
    ("mapping entry while :00 != 0", "*", [], ("w", 0x1600, 1, u(0x60400010, 4), {}), 0x06010003),
    ("assignment entry while :00 != 0", "hcfa-am0520b", [], ("w", 0x1C12, 1, u(0x1601, 2), {}), 0x06010003),
    ("map statusword into an RxPDO", "*", [(0x1600, 0, u(0, 1))], ("w", 0x1600, 1, u(0x60410010, 4), {}),
     0x06040041),
    ("map controlword into a TxPDO", "*", [(0x1A00, 0, u(0, 1))], ("w", 0x1A00, 1, u(0x60400010, 4), {}),
     0x06040041),
    ("map 6502h (not mappable)", "*", [(0x1A00, 0, u(0, 1))], ("w", 0x1A00, 1, u(0x65020020, 4), {}),
     0x06040041),
    ("map a missing object", "*", [(0x1600, 0, u(0, 1))], ("w", 0x1600, 1, u(0x60070010, 4), {}), 0x06020000),
    ("map with a wrong bit length", "*", [(0x1600, 0, u(0, 1))], ("w", 0x1600, 1, u(0x60400020, 4), {}),
     0x06040043),
    ("nine entries in one PDO", "*", [(0x1600, 0, u(0, 1))], ("w", 0x1600, 0, u(9, 1), {}), 0x06040042),
    ("count over an empty entry", "*", [(0x1601, 0, u(0, 1))], ("w", 0x1601, 0, u(8, 1), {}), 0x06040041),
    ("12 bytes in a CAN PDO", "kinco-servo",
     [(0x1602, 0, u(0, 1)), (0x1602, 1, u(0x607A0020, 4)), (0x1602, 2, u(0x60810020, 4)),
      (0x1602, 3, u(0x60830020, 4))],
     ("w", 0x1602, 0, u(3, 1), {}), 0x06040042),
]


def _cases():
    for case, model, prep, op, code in ABORTS:
        models = ["hcfa-am0520b", "kinco-servo"] if model == "*" else [model]
        for m in models:
            yield pytest.param(m, prep, op, code, id=f"{m}: {case}")


@pytest.mark.parametrize("model, prep, op, code", list(_cases()))
def test_sdo_abort(model: str, prep: list, op: tuple, code: int) -> None:
    """Each refused SDO transfer aborts with the code of digest §6.3, leaves
    the value unchanged and explains itself with the object and a manual
    section."""
    store = Store(ObjectDictionary.load(model))
    for index, sub, data in prep:
        store.sdo_write(index, sub, data)
    before = {(e.index, e.sub): store.stored(e.index, e.sub) for e in store.od}
    with pytest.raises(SdoAbort) as info:
        if op[0] == "r":
            store.sdo_read(op[1], op[2])
        else:
            store.sdo_write(op[1], op[2], op[3], **op[4])
    abort = info.value
    assert abort.code == code, str(abort)
    assert isinstance(abort, PlcError)
    assert f"0x{code:08X}" in str(abort)
    assert f"{op[1]:04X}h" in abort.explanation
    assert "§" in abort.explanation or "CiA" in abort.explanation
    assert {(e.index, e.sub): store.stored(e.index, e.sub) for e in store.od} == before


def test_explanation_names_object_value_and_section() -> None:
    """The refusal text names the object, its name, the value and where the
    limit comes from."""
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    with pytest.raises(SdoAbort) as info:
        store.sdo_write(0x2000, 2, u(51201, 2))
    text = info.value.explanation
    assert "2000h:02" in text and "Microsteps" in text and "51201" in text
    assert "51200" in text and "HCFA §5.1" in text


def test_generic_length_abort() -> None:
    """length_abort="generic" gives 0x06070010 for any wrong length, as
    canopen's SDO server does."""
    store = Store(ObjectDictionary.load("hcfa-am0520b"), length_abort="generic")
    for data in (u(6, 1), u(6, 4)):
        with pytest.raises(SdoAbort) as info:
            store.sdo_write(0x6040, 0, data)
        assert info.value.code == 0x06070010


def test_bad_store_options_and_state() -> None:
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    with pytest.raises(PlcConfigError, match="ESM state 'BOOT'"):
        store.sdo_write(0x6040, 0, u(6, 2), state="BOOT")
    with pytest.raises(PlcConfigError, match="length_abort"):
        Store(store.od, length_abort="loose")


def test_read_of_write_only(tmp_path) -> None:
    """Neither drive model has a write-only object; a dictionary with one
    refuses the upload with 0x06010001 and still accepts the download."""
    for model in ("hcfa-am0520b", "kinco-servo"):
        assert not [e for e in ObjectDictionary.load(model) if e.access == "wo"]
    path = tmp_path / "wo.toml"
    path.write_text('[model]\nname = "wo"\n[dictionary]\nentries = [\n'
                    '  { index = 0x2100, sub = 0, name = "Command", type = "U16", access = "wo", '
                    'default = 0, source = "test" },\n]\n', encoding="utf-8")
    store = Store(ObjectDictionary.from_file(path))
    with pytest.raises(SdoAbort) as info:
        store.sdo_read(0x2100, 0)
    assert info.value.code == 0x06010001
    store.sdo_write(0x2100, 0, u(7, 2))
    assert store.get(0x2100) == 7


def test_round_trip_of_every_writable_entry(od: ObjectDictionary) -> None:
    """Every rw entry takes its own default back over SDO (in PRE-OP with the
    maps and assignments emptied first) and reads back the same bytes."""
    store = Store(od)
    heads = [e for e in od if e.sub == 0 and e.when == "preop"]
    for e in heads:
        store.sdo_write(e.index, 0, u(0, 1))
    for e in od:
        if e.access != "rw":
            continue
        data = e.encode(e.default)
        if e.sub == 0 and e.when == "preop":
            continue
        store.sdo_write(e.index, e.sub, data)
        assert store.sdo_read(e.index, e.sub) == data
    for e in reversed(heads):
        store.sdo_write(e.index, 0, e.encode(e.default))
    assert all(store.get(e.index, e.sub) == e.default for e in od)


def test_little_endian_encoding() -> None:
    """CoE data is little-endian; signed types are two's complement."""
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    store.sdo_write(0x607A, 0, i(-1000, 4))
    assert store.get(0x607A) == -1000
    assert store.sdo_read(0x607A, 0) == bytes.fromhex("18fcffff")
    assert store.sdo_read(0x1000, 0) == bytes.fromhex("92010200")
    assert store.sdo_read(0x1008, 0) == b"AM0520B"
    assert store.sdo_read(0x6080, 0) == u(833333, 4)


# -- power-up parameters (HCFA §5.1 再次通电) ----------------------------------

def test_power_up_parameter_waits_for_power_cycle() -> None:
    """A power-up parameter is stored and read back at once, flagged pending,
    but the active value changes only at the power cycle, which says so."""
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    seen: list[Write] = []
    store.on_write(seen.append)
    store.sdo_write(0x2000, 1, u(1, 2))  # P00.01 direction: power-up, stopped
    assert store.get(0x2000, 1) == 0
    assert store.stored(0x2000, 1) == 1
    assert store.sdo_read(0x2000, 1) == u(1, 2)
    assert store.pending == {(0x2000, 1): 1}
    assert seen[-1].pending and seen[-1].value == 1 and seen[-1].old == 0
    assert store.events[-1].kind == "pending" and "power-up" in store.events[-1].text
    events = store.power_cycle()
    assert [(e.kind, e.index, e.sub, e.value) for e in events] == [("applied", 0x2000, 1, 1)]
    assert "2000h:01" in events[0].text and "HCFA §5.1" in events[0].text
    assert store.get(0x2000, 1) == 1 and store.pending == {}
    assert store.power_cycle() == []


def test_power_up_parameter_written_back_to_active_value() -> None:
    """Writing the active value again cancels a pending change."""
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    store.sdo_write(0x2001, 10, u(50, 2))  # P01.10: power-up
    store.sdo_write(0x2001, 10, u(30, 2))
    assert store.pending == {}
    assert store.get(0x2001, 10) == 30


def test_immediate_parameter_acts_at_once() -> None:
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    store.sdo_write(0x2000, 2, u(10000, 2))  # P00.02: now, any
    assert store.get(0x2000, 2) == 10000 and store.pending == {}


def test_kinco_has_no_power_up_or_stopped_only_entries() -> None:
    """The Kinco note gives no such rules; its dictionary has none."""
    od = ObjectDictionary.load("kinco-servo")
    assert {e.effect for e in od} == {"now"}
    assert {e.when for e in od} == {"any", "preop"}


# -- stopped-only parameters (HCFA §5.1 停机设定) -------------------------------

@pytest.mark.parametrize("index, sub, value", [(0x2003, 7, 100), (0x2002, 10, 1), (0x2000, 20, 0xC81)])
def test_stopped_only_parameter(index: int, sub: int, value: int) -> None:
    """Refused while moving with 0x08000022; accepted at standstill."""
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    with pytest.raises(SdoAbort) as info:
        store.sdo_write(index, sub, u(value, 2), moving=True)
    assert info.value.code == 0x08000022 and "stopped" in info.value.explanation
    store.sdo_write(index, sub, u(value, 2), moving=False)
    assert store.get(index, sub) == value


def test_running_parameter_while_moving() -> None:
    """A "运行设定" parameter (P00.04) and profile objects take writes while moving."""
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    store.sdo_write(0x2000, 4, u(40, 2), moving=True)
    store.sdo_write(0x607A, 0, i(5000, 4), moving=True, state="OP")
    assert store.get(0x2000, 4) == 40 and store.get(0x607A) == 5000


# -- the dynamic mapping procedure (HCFA §6.7.4 steps A-H) ---------------------

def test_hcfa_mapping_procedure() -> None:
    """Steps B-G in PRE-OP: clear the assignment, clear a map, write entries,
    set the count, assign, set the assignment count."""
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    w = store.sdo_write
    w(0x1C12, 0, u(0, 1))                       # B
    w(0x1C13, 0, u(0, 1))
    w(0x1601, 0, u(0, 1))                       # C
    entries = [0x60400010, 0x607A0020, 0x60810020, 0x60830020, 0x60840020, 0x60600008,
               0x60980008, 0x607C0020]
    for k, value in enumerate(entries, 1):      # D
        w(0x1601, k, u(value, 4))
    w(0x1601, 0, u(8, 1))                       # E: 8 entries, 26 bytes
    w(0x1C12, 1, u(0x1601, 2))                  # F
    w(0x1C12, 2, u(0x1603, 2))
    w(0x1C12, 0, u(2, 1))                       # G
    w(0x1C13, 0, u(1, 1))
    assert [store.get(0x1601, k) for k in range(1, 9)] == entries
    assert [(e.index, e.sub) for e in store.mapped(0x1601)] == [(v >> 16, (v >> 8) & 0xFF) for v in entries]
    assert (store.get(0x1C12, 0), store.get(0x1C12, 1), store.get(0x1C12, 2)) == (2, 0x1601, 0x1603)


def test_hcfa_pdo_of_exactly_32_bytes() -> None:
    """Eight 32-bit objects fill a PDO exactly (HCFA §6.7.2: 8 objects, 32
    bytes); with no 64-bit object the byte limit cannot be passed on this drive."""
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    store.sdo_write(0x1A01, 0, u(0, 1))
    objs = [0x6064, 0x606C, 0x6062, 0x6063, 0x60F4, 0x60BA, 0x60BB, 0x60FD]
    for k, index in enumerate(objs, 1):
        store.sdo_write(0x1A01, k, u(index << 16 | 32, 4))
    store.sdo_write(0x1A01, 0, u(8, 1))
    assert store.get(0x1A01, 0) == 8
    assert max(e.bits for e in store.od if e.pdo) <= 32


@pytest.mark.parametrize("model", ["hcfa-am0520b", "kinco-servo"])
def test_default_maps_resolve(model: str) -> None:
    """Every default map resolves to its objects; a non-map index is refused."""
    store = Store(ObjectDictionary.load(model))
    assert [e.index for e in store.mapped(0x1600)][0] == 0x6040
    assert [e.index for e in store.mapped(0x1A00)][0] == 0x6041
    with pytest.raises(SdoAbort) as info:
        store.mapped(0x6040)
    assert info.value.code == 0x06020000


def test_kinco_can_pdo_of_8_bytes() -> None:
    """A CAN PDO carries 8 bytes: two 32-bit objects fit."""
    store = Store(ObjectDictionary.load("kinco-servo"))
    store.sdo_write(0x1602, 0, u(0, 1))
    store.sdo_write(0x1602, 1, u(0x607A0020, 4))
    store.sdo_write(0x1602, 2, u(0x60810020, 4))
    store.sdo_write(0x1602, 0, u(2, 1))
    assert store.get(0x1602, 0) == 2


def test_mapping_entry_may_be_cleared() -> None:
    """Entry 0 (empty) is accepted beyond the count."""
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    store.sdo_write(0x1600, 0, u(0, 1))
    store.sdo_write(0x1600, 3, u(0, 4))
    store.sdo_write(0x1600, 0, u(2, 1))
    assert store.get(0x1600, 0) == 2


# -- hooks --------------------------------------------------------------------

def test_on_write_sees_sdo_and_pdo_writes_but_not_drive_updates() -> None:
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    seen: list[Write] = []
    unsubscribe = store.on_write(seen.append)
    store.sdo_write(0x6040, 0, u(6, 2), state="OP")
    store.set(0x6040, 0, 7, source="pdo")
    store.set(0x6041, 0, 0x0231)
    assert [(w.entry.index, w.value, w.old, w.source) for w in seen] == [
        (0x6040, 6, 0, "sdo"), (0x6040, 7, 6, "pdo")]
    assert store.get(0x6041) == 0x0231
    unsubscribe()
    store.sdo_write(0x6040, 0, u(15, 2))
    assert len(seen) == 2


def test_on_check_can_refuse_a_write() -> None:
    """A subscriber refusing a write (e.g. the state machine) aborts the
    transfer with its own code; nothing is stored and on_write is not called."""
    store = Store(ObjectDictionary.load("kinco-servo"))
    seen: list[Write] = []
    store.on_write(seen.append)

    def veto(write: Write) -> None:
        if write.entry.index == 0x6060 and write.value == 6:
            raise SdoAbort(0x08000022, "6060h := 6 refused while moving (test)")

    store.on_check(veto)
    with pytest.raises(SdoAbort) as info:
        store.sdo_write(0x6060, 0, i(6, 1))
    assert info.value.code == 0x08000022
    assert store.get(0x6060) == 0 and seen == []
    store.sdo_write(0x6060, 0, i(1, 1))
    assert store.get(0x6060) == 1 and len(seen) == 1


def test_set_checks_the_type() -> None:
    store = Store(ObjectDictionary.load("hcfa-am0520b"))
    with pytest.raises(PlcConfigError, match="6041h:00"):
        store.set(0x6041, 0, 0x10000)
    with pytest.raises(SdoAbort):
        store.set(0x6042, 0, 1)
    store.set(0x6064, 0, -(1 << 31))
    assert store.sdo_read(0x6064, 0) == bytes.fromhex("00000080")


def test_range_limits_of_every_entry(od: ObjectDictionary) -> None:
    """For every writable entry: its min and max are accepted, one beyond
    aborts with 0x06090032 / 0x06090031 (when the type can carry it), and a
    value outside ``values`` aborts with 0x06090030."""
    from plcrt.devices.cia402.od import DTYPES
    store = Store(od)
    for e in od:
        if e.access != "rw" or e.dtype == "STR" or e.when == "preop":
            continue
        lo, hi = DTYPES[e.dtype][1:]
        if e.values is not None:
            for v in e.values:
                store.sdo_write(e.index, e.sub, e.encode(v))
            outside = next(v for v in range(lo, hi + 1) if v not in e.values)
            with pytest.raises(SdoAbort) as info:
                store.sdo_write(e.index, e.sub, e.encode(outside))
            assert info.value.code == 0x06090030, e.label
            continue
        for v in (e.low, e.high):
            store.sdo_write(e.index, e.sub, e.encode(v))
            assert store.stored(e.index, e.sub) == v
        for v, code in ((e.low - 1, 0x06090032), (e.high + 1, 0x06090031)):
            if lo <= v <= hi:
                with pytest.raises(SdoAbort) as info:
                    store.sdo_write(e.index, e.sub, e.encode(v))
                assert info.value.code == code, e.label


@given(data=st.data())
@settings(max_examples=60, deadline=None)
def test_sdo_bytes_round_trip(data: st.DataObject) -> None:
    """Any in-range value of any writable entry goes down and up the SDO path
    unchanged, as little-endian bytes of the entry's size."""
    od = ObjectDictionary.load(data.draw(st.sampled_from(["hcfa-am0520b", "kinco-servo"])))
    entries = [e for e in od if e.access == "rw" and e.dtype != "STR" and e.when != "preop"]
    e = data.draw(st.sampled_from(entries))
    value = data.draw(st.sampled_from(e.values) if e.values else st.integers(e.low, e.high))
    store = Store(od)
    store.sdo_write(e.index, e.sub, e.encode(value))
    raw = store.sdo_read(e.index, e.sub)
    assert len(raw) == e.size
    assert int.from_bytes(raw, "little", signed=e.dtype.startswith("I")) == value
