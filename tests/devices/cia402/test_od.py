"""The drive models' object dictionaries as data: loading, the located errors
of malformed files, the rows the manuals give (HCFA §5.1, §8, digest §3),
the canopen ObjectDictionary built from them, the EDS round trip through
canopen.import_od, and the ``plcrt cia402 eds`` command."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from plcrt.cia402 import eds_text, models, object_dictionary
from plcrt.cli import main
from plcrt.devices.cia402.od import DTYPES, Entry, ObjectDictionary, SdoAbort
from plcrt.errors import PlcConfigError

MODELS = ["hcfa-am0520b", "kinco-servo"]


def test_models_listed() -> None:
    assert ObjectDictionary.models() == MODELS == models()


def test_unknown_model_names_the_known_ones() -> None:
    with pytest.raises(PlcConfigError) as info:
        ObjectDictionary.load("hcfa-am0520")
    assert "'hcfa-am0520'" in str(info.value)
    assert "hcfa-am0520b, kinco-servo" in str(info.value)
    with pytest.raises(PlcConfigError, match="known models"):
        object_dictionary("nope")
    with pytest.raises(PlcConfigError, match="known models"):
        ObjectDictionary.load("../cia402/hcfa-am0520b")


@pytest.mark.parametrize("model", MODELS)
def test_every_row_is_well_formed(model: str) -> None:
    """Each entry has a known type, access and rule, a default inside its
    range, a manual section, and each record a U8 subindex 0."""
    od = ObjectDictionary.load(model)
    assert od.model == model
    for e in od:
        assert e.dtype in DTYPES and e.access in ("ro", "rw", "wo", "const")
        assert e.pdo in ("rx", "tx", "") and e.effect in ("now", "power-up")
        assert e.when in ("any", "stopped", "preop")
        assert e.source
        if e.dtype != "STR":
            assert e.low <= int(e.default) <= e.high
        if e.pdo == "rx":
            assert e.access == "rw", e.label
    for index in od.indexes():
        subs = od.subs(index)
        if len(subs) > 1:
            assert subs[0].sub == 0 and subs[0].dtype == "U8"


def test_entry_bits_and_lookup() -> None:
    od = ObjectDictionary.load("hcfa-am0520b")
    assert od.entry(0x6040, 0).bits == 16
    assert od.entry(0x6060, 0).bits == 8
    assert od.entry(0x607A, 0).bits == 32
    assert od.entry(0x1C32, 32).bits == 1 and od.entry(0x1C32, 32).size == 1
    assert od.entry(0x1008, 0).bits == 8 * len("AM0520B")
    assert (0x6041, 0) in od and (0x6041, 1) not in od
    assert od.find(0x6007, 0) is None
    with pytest.raises(SdoAbort) as info:
        od.entry(0x6007, 0)
    assert info.value.code == 0x06020000 and "HCFA §8.1" in info.value.explanation
    with pytest.raises(SdoAbort) as info:
        od.entry(0x6099, 3)
    assert info.value.code == 0x06090011 and "00, 01, 02" in info.value.explanation
    assert len(od) == len(list(od))
    with pytest.raises(AttributeError):
        od.entry(0x6040, 0).index = 1  # type: ignore[misc]


# -- HCFA rows (digest §3) -----------------------------------------------------

HCFA_PARAMS = {  # Pgg.nn -> (min, max, default, effect, when), HCFA §5.1 / §8.2
    "P00.01": (0, 1, 0, "power-up", "stopped"), "P00.02": (200, 51200, 50000, "now", "any"),
    "P00.03": (50, 10000, 300, "now", "any"), "P00.04": (0, 100, 50, "now", "any"),
    "P00.06": (0, 1, 0, "now", "stopped"), "P00.07": (0, 1, 0, "now", "stopped"),
    "P00.08": (0, 1, 0, "now", "stopped"), "P00.09": (0, 1, 0, "power-up", "stopped"),
    "P00.11": (0, 100, 60, "now", "any"), "P00.13": (0, 65535, 4000, "now", "any"),
    "P00.14": (0, 1, 1, "power-up", "stopped"), "P00.15": (0, 1, 1, "power-up", "stopped"),
    "P00.17": (0, 100, 60, "now", "any"), "P00.20": (0, 65535, 0xC83, "now", "stopped"),
    "P00.21": (200, 65535, 1000, "power-up", "stopped"), "P00.22": (0, 65535, 2000, "now", "any"),
    "P00.24": (0, 65535, 0, "now", "stopped"), "P01.01": (1, 6, 4, "power-up", "stopped"),
    "P01.08": (0, 65535, 10000, "now", "any"), "P01.10": (20, 100, 30, "power-up", "stopped"),
    "P02.01": (0, 65535, 4, "now", "stopped"), "P02.02": (0, 65535, 2, "now", "stopped"),
    "P02.03": (0, 65535, 1, "now", "stopped"), "P02.04": (0, 65535, 8, "now", "stopped"),
    "P02.05": (0, 65535, 16, "now", "stopped"), "P02.10": (0, 65535, 0, "now", "stopped"),
    "P02.21": (0, 65535, 3, "now", "any"), "P02.22": (0, 65535, 3, "now", "any"),
    "P02.23": (0, 65535, 3, "now", "any"), "P02.24": (0, 65535, 3, "now", "any"),
    "P02.25": (0, 65535, 3, "now", "any"), "P02.29": (1, 4, 1, "now", "stopped"),
    "P02.30": (1, 4, 2, "now", "stopped"), "P02.31": (1, 4, 3, "now", "stopped"),
    "P02.32": (0, 65535, 0, "now", "any"), "P03.01": (0, 10000, 1000, "now", "any"),
    "P03.02": (0, 10000, 1000, "now", "any"), "P03.03": (0, 1, 1, "now", "any"),
    "P03.04": (50, 25600, 12000, "now", "any"), "P03.07": (0, 65535, 0, "now", "stopped"),
    "P03.08": (100, 65535, 100, "now", "stopped"), "P03.09": (100, 1500, 300, "power-up", "stopped"),
    "P03.10": (100, 65535, 100, "now", "stopped"), "P03.11": (10, 10000, 1000, "now", "stopped"),
    "P03.13": (0, 100, 50, "now", "stopped"), "P04.03": (0, 10000, 100, "now", "stopped"),
    "P04.04": (10, 10000, 100, "now", "stopped"), "P04.05": (0, 100, 1, "now", "stopped"),
}
P18 = [1, 3, 4, 5, 6, 9, 12, 21, 29, 30, 31, 35, 36, 37, 38, 39]


def test_hcfa_vendor_parameters_follow_the_index_rule() -> None:
    """Pgg.nn is 2000h+gg : nn, U16 rw, with the §5.1 range, default and
    taking-effect rules; P18 is read-only; nothing else is in 2000h-5FFFh."""
    od = ObjectDictionary.load("hcfa-am0520b")
    for param, (lo, hi, default, effect, when) in HCFA_PARAMS.items():
        gg, nn = map(int, re.match(r"P(\d\d)\.(\d\d)", param).groups())
        e = od.entry(0x2000 + gg, nn)
        assert e.name.startswith(param)
        assert (e.dtype, e.access, e.pdo) == ("U16", "rw", "")
        assert (e.low, e.high, e.default, e.effect, e.when) == (lo, hi, default, effect, when), param
    for nn in P18:
        e = od.entry(0x2012, nn)
        assert e.name.startswith(f"P18.{nn:02d}") and e.access == "ro" and e.dtype == "U16"
    vendor = [e for e in od if 0x2000 <= e.index <= 0x5FFF and e.sub > 0]
    assert len(vendor) == len(HCFA_PARAMS) + len(P18)
    assert od.entry(0x2012, 39).index == 0x2012 and od.entry(0x2012, 39).sub == 0x27  # P18.39


def test_hcfa_default_pdo_maps() -> None:
    """Counts of HCFA §8.1 with the entries of digest §3.4; 1600h and 1A00h
    assigned (1C12h/1C13h U16)."""
    od = ObjectDictionary.load("hcfa-am0520b")
    maps = {0x1600: [0x6040, 0x607A, 0x60B8], 0x1601: [0x6040, 0x607A, 0x6081, 0x6083, 0x6084, 0x6060],
            0x1602: [0x6040, 0x60FF, 0x6083, 0x6084, 0x6060],
            0x1603: [0x6040, 0x6098, 0x6099, 0x6099, 0x609A, 0x607C, 0x6060],
            0x1A00: [0x6041, 0x603F, 0x6064, 0x606C, 0x6061, 0x60B9, 0x60BA], 0x1A01: []}
    for index, objs in maps.items():
        assert od.entry(index, 0).default == len(objs)
        assert [int(od.entry(index, k).default) >> 16 for k in range(1, len(objs) + 1)] == objs
        assert all(od.entry(index, k).default == 0 for k in range(len(objs) + 1, 9))
        assert all(e.when == "preop" and e.access == "rw" for e in od.subs(index))
    assert [od.entry(0x1C12, k).default for k in range(5)] == [1, 0x1600, 0, 0, 0]
    assert [od.entry(0x1C13, k).default for k in range(3)] == [1, 0x1A00, 0]
    assert od.entry(0x1C12, 1).dtype == "U16"
    assert [od.entry(0x1C00, k).default for k in range(5)] == [4, 1, 2, 3, 4]


@pytest.mark.parametrize("index, sub, dtype, access, pdo, default", [
    (0x1000, 0, "U32", "ro", "", 0x00020192), (0x1018, 1, "U32", "ro", "", 0xFFFF0000),
    (0x10F1, 1, "U32", "rw", "", 65536), (0x603F, 0, "U16", "ro", "tx", 0),
    (0x6040, 0, "U16", "rw", "rx", 0), (0x6041, 0, "U16", "ro", "tx", 0),
    (0x605A, 0, "I16", "rw", "", 2), (0x6060, 0, "I8", "rw", "rx", 8), (0x6061, 0, "I8", "ro", "tx", 8),
    (0x6065, 0, "U32", "rw", "rx", 0xFFFFFFFF), (0x6080, 0, "U32", "rw", "rx", 833333),
    (0x6083, 0, "U32", "rw", "rx", 0), (0x6098, 0, "I8", "rw", "rx", 1),
    (0x6099, 1, "U32", "rw", "rx", 83333), (0x6099, 2, "U32", "rw", "rx", 41666),
    (0x609A, 0, "U32", "rw", "rx", 833333), (0x60B9, 0, "U16", "ro", "tx", 0),
    (0x60FE, 1, "U32", "rw", "rx", 1), (0x60FF, 0, "I32", "rw", "rx", 0), (0x6502, 0, "U32", "ro", "", 165),
])
def test_hcfa_profile_objects(index: int, sub: int, dtype: str, access: str, pdo: str,
                              default: int) -> None:
    """Digest §3.1/§3.2: standard sizes where the manual's differ."""
    e = ObjectDictionary.load("hcfa-am0520b").entry(index, sub)
    assert (e.dtype, e.access, e.pdo, e.default) == (dtype, access, pdo, default)


def test_hcfa_corrections() -> None:
    """The identity is at 1018h (not 1008h:01-04); 10F1h uses ETG subindexes."""
    od = ObjectDictionary.load("hcfa-am0520b")
    assert [e.sub for e in od.subs(0x1008)] == [0]
    assert [e.sub for e in od.subs(0x10F1)] == [0, 1, 2]
    assert od.entry(0x6060, 0).values == (0, 1, 3, 6, 8)


def test_kinco_homing_objects() -> None:
    """Kinco §2.1: 6099h:01-06, methods -18..35, 60F9h:0A velocity window."""
    od = ObjectDictionary.load("kinco-servo")
    assert [e.sub for e in od.subs(0x6099)] == [0, 1, 2, 3, 4, 5, 6]
    methods = set(od.entry(0x6098, 0).values)
    assert methods == {-18, -17} | set(range(1, 15)) | set(range(17, 31)) | {33, 34, 35}
    assert (od.entry(0x6099, 5).low, od.entry(0x6099, 5).high) == (0, 1)
    assert (od.entry(0x6099, 6).high, od.entry(0x6099, 3).high) == (2, 2)
    assert od.entry(0x60F9, 10).name == "Velocity window"
    silent = [e for e in od if "Kinco note silent" in e.source]
    assert silent and all("CiA" in e.source for e in silent)
    assert od.pdo_max_bytes == 8


# -- malformed files -------------------------------------------------------------

def row(**keys: str | None) -> str:
    """A one-line TOML entry: a valid controlword row with some keys
    replaced (value None drops the key)."""
    base = {"index": "0x6040", "sub": "0", "name": '"Controlword"', "type": '"U16"',
            "access": '"rw"', "default": "0", "source": '"x"'}
    base.update(keys)
    return "{ " + ", ".join(f"{k} = {v}" for k, v in base.items() if v is not None) + " }"


GOOD = row()


@pytest.mark.parametrize("bad, message", [
    (row(type='"U17"'), "type = 'U17'"),
    (row(access='"rx"'), "access = 'rx'"),
    (row(default=None), "missing key 'default'"),
    (row(default="70000"), "default = 70000 is outside the range of U16"),
    (row(default="5", min="6"), "default 5 is outside 6..65535"),
    (row(colour="1"), "unknown key 'colour'"),
    (row(when='"later"'), "when = 'later'"),
    (row(index='"6040"'), "index must be an integer"),
    (row(index="0x6041", min="9", max="3"), "min 9 is above max 3"),
    (row(index="0x6060", type='"I8"', default="2", values="[1, 3]"), "default 2 is not one of the values"),
    (GOOD, "duplicate entry"),
    (row(index="0x1600", sub="1", type='"U32"', default="0x60400010"), "has subindexes but no U8 subindex 0"),
])
def test_malformed_row_is_located(tmp_path: Path, bad: str, message: str) -> None:
    """A bad row is a PlcConfigError naming the file, the row's line and the
    entry, never a traceback."""
    path = tmp_path / "bad.toml"
    path.write_text(f'[model]\nname = "bad"\n[dictionary]\nentries = [\n  {GOOD},\n  {bad},\n]\n',
                    encoding="utf-8")
    with pytest.raises(PlcConfigError) as info:
        ObjectDictionary.from_file(path)
    text = str(info.value)
    assert message in text
    assert f"{path}:6:" in text
    assert info.value.loc is not None and info.value.loc.line == 6


def test_invalid_default_mapping_is_located(tmp_path: Path) -> None:
    """A default map naming a TxPDO object in an RxPDO is refused at load."""
    path = tmp_path / "map.toml"
    rows = [row(index="0x1600", name='"n"', type='"U8"', default="1"),
            row(index="0x1600", sub="1", name='"e"', type='"U32"', default="0x60410010"),
            row(index="0x6041", name='"S"', access='"ro"', pdo='"tx"')]
    path.write_text('[model]\nname = "map"\n[dictionary]\nentries = [\n'
                    + "".join(f"  {r},\n" for r in rows) + "]\n", encoding="utf-8")
    with pytest.raises(PlcConfigError,
                       match=r"map\.toml:6:1: error: 1600h:01 .*default mapping is invalid.*TXPDO"):
        ObjectDictionary.from_file(path)


@pytest.mark.parametrize("text, message", [
    ("[model\n", "cannot read object dictionary"),
    ('[dictionary]\nentries = []\n', "missing [model] table"),
    ('[model]\nname = "x"\n', "missing [dictionary] table"),
    ('[model]\nname = "x"\ndictionary = 5\n', "missing [dictionary] table"),
])
def test_malformed_file(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "f.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(PlcConfigError) as info:
        ObjectDictionary.from_file(path)
    assert message in str(info.value) and str(path) in str(info.value)


# -- canopen and EDS -------------------------------------------------------------

@pytest.mark.parametrize("model", MODELS)
def test_canopen_object_dictionary(model: str) -> None:
    """Every entry appears in the canopen OD with its type, access, default,
    limits and PDO mappability."""
    from canopen.objectdictionary import ODRecord, ODVariable
    od = ObjectDictionary.load(model)
    co = object_dictionary(model)
    for e in od:
        var = co[e.index] if len(od.subs(e.index)) == 1 and e.sub == 0 else co[e.index][e.sub]
        assert isinstance(var, ODVariable)
        _same(e, var)
    assert isinstance(co[0x6099], ODRecord) and co[0x6099].name.startswith("Homing")
    assert co["Controlword"].index == 0x6040


@pytest.mark.parametrize("model", MODELS)
def test_eds_round_trip(model: str, tmp_path: Path) -> None:
    """The EDS text read back by canopen.import_od has the same objects,
    types, access, defaults, limits and mappability; it is reproducible."""
    import canopen
    text = eds_text(model)
    assert text == eds_text(model)
    path = tmp_path / f"{model}.eds"
    path.write_text(text, encoding="utf-8")
    co = canopen.import_od(str(path))
    od = ObjectDictionary.load(model)
    assert sorted(co.indices) == od.indexes()
    for e in od:
        var = co[e.index] if len(od.subs(e.index)) == 1 and e.sub == 0 else co[e.index][e.sub]
        _same(e, var)


def _same(e: Entry, var) -> None:
    codes = {"BOOL": 1, "I8": 2, "I16": 3, "I32": 4, "U8": 5, "U16": 6, "U32": 7, "STR": 9}
    assert (var.index, var.subindex, var.name) == (e.index, e.sub, e.name)
    assert var.data_type == codes[e.dtype], e.label
    assert var.access_type == e.access, e.label
    assert bool(var.pdo_mappable) == bool(e.pdo), e.label
    if e.dtype == "STR":
        assert var.default == e.default
    else:
        assert int(var.default) == e.default, e.label
        assert (var.min, var.max) == (e.min, e.max), e.label


def test_cli_eds(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`plcrt cia402 eds MODEL` prints the EDS; -o writes it; an unknown model
    is a one-line error with exit status 1."""
    assert main(["cia402", "eds", "kinco-servo"]) == 0
    assert capsys.readouterr().out == eds_text("kinco-servo")
    out = tmp_path / "hcfa.eds"
    assert main(["cia402", "eds", "hcfa-am0520b", "-o", str(out)]) == 0
    assert out.read_text(encoding="utf-8") == eds_text("hcfa-am0520b")
    assert "[6040]" in out.read_text(encoding="utf-8")
    assert main(["cia402", "eds", "hcfa"]) == 1
    err = capsys.readouterr().err
    assert "unknown CiA 402 drive model 'hcfa'" in err and "Traceback" not in err
    assert main(["cia402", "eds", "kinco-servo", "-o", str(tmp_path / "no" / "x.eds")]) == 1
    assert "cannot write" in capsys.readouterr().err
    assert main(["cia402", "models"]) == 0
    assert capsys.readouterr().out.split() == MODELS
