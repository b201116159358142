"""The memory image: big-endian aliasing, area sizes per CPU, numpy views,
snapshots and diffs."""

from __future__ import annotations

import numpy as np
import pytest

import plcrt
from plcrt.memory import CPU_MODELS, MemoryImage, cpu_model

OB1 = "ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD     SM0.0\n{body}END_ORGANIZATION_BLOCK\n"


def _plc(body: str = "", **kw) -> plcrt.Plc:
    return plcrt.load(OB1.format(body=body), **kw)


def test_word_is_big_endian_over_two_bytes() -> None:
    """VW100 = VB100 (high byte) : VB101 (low byte)."""
    plc = _plc("MOVW   16#1234, VW100\n")
    plc.scan()
    assert (plc["VB100"], plc["VB101"]) == (0x12, 0x34)


def test_dword_overlaps_words_and_odd_addresses_are_legal() -> None:
    """VD100 covers VW100 and VW102; VW101 straddles them."""
    plc = _plc("MOVD   16#11223344, VD100\n")
    plc.scan()
    assert plc["VW100"] == 0x1122
    assert plc["VW102"] == 0x3344
    assert plc["VW101"] == 0x2233
    assert plc["V100.4"] == 1 and plc["V100.0"] == 1 and plc["V100.1"] == 0


def test_words_read_signed_bytes_unsigned() -> None:
    """Words and double words read signed, bytes unsigned (status chart style)."""
    plc = _plc("MOVW   16#FFFF, VW0\nMOVD   16#FFFFFFFE, VD10\n")
    plc.scan()
    assert plc["VW0"] == -1 and plc["VB0"] == 255 and plc["VD10"] == -2


@pytest.mark.parametrize("name,v_bytes", [("CPU221", 2048), ("CPU222", 2048), ("CPU224", 8192),
                                          ("CPU224XP", 10240), ("CPU226", 10240)])
def test_v_size_follows_cpu_model(name: str, v_bytes: int) -> None:
    """V memory size comes from the CPU model table; the last byte is addressable."""
    assert cpu_model(name).v_bytes == v_bytes
    plc = _plc(f"MOVB   7, VB{v_bytes - 1}\n", cpu=name)
    plc.scan()
    assert plc[f"VB{v_bytes - 1}"] == 7
    with pytest.raises(plcrt.PlcCompileError, match="out of range"):
        _plc(f"MOVB   7, VB{v_bytes}\n", cpu=name)


def test_default_cpu_is_226() -> None:
    """Without a CPU name the model is CPU 226."""
    assert _plc().model is CPU_MODELS["CPU226"]


def test_unknown_cpu_is_a_config_error() -> None:
    """An unknown CPU name is a clear configuration error."""
    with pytest.raises(plcrt.PlcConfigError, match="unknown CPU model"):
        cpu_model("CPU999")


def test_numpy_view_shares_bytes() -> None:
    """view() is a zero-copy window on the same bytes the program writes."""
    plc = _plc("MOVB   42, VB3\n")
    view = plc.mem.view("V")
    plc.scan()
    assert view[3] == 42
    view[4] = 9
    assert plc["VB4"] == 9
    assert view.dtype == np.uint8


def test_snapshot_and_diff() -> None:
    """diff() lists exactly the bytes changed since a snapshot; restore() undoes them."""
    img = MemoryImage(cpu_model(None))
    snap = img.snapshot()
    img.areas["V"][5] = 1
    img.areas["Q"][0] = 3
    changes = img.diff(snap)
    assert set(changes) == {"V", "Q"}
    assert changes["V"].tolist() == [5]
    img.restore(snap)
    assert img.diff(snap) == {}


@pytest.mark.parametrize("addr", ["VW", "I0.9", "VB99999", "XYZ1", "T300", "AC4", "HC6"])
def test_bad_addresses_in_the_api(addr: str) -> None:
    """Reading a malformed or out-of-range address raises PlcAddressError."""
    with pytest.raises(plcrt.PlcAddressError):
        _plc()[addr]


def test_api_write_range_checked() -> None:
    """Writing a value that does not fit the width is refused."""
    plc = _plc()
    with pytest.raises(plcrt.PlcAddressError):
        plc["VB0"] = 256
    plc["VW0"] = -32768
    assert plc["VW0"] == -32768
    plc["VD0"] = 1.5
    assert plc.read("VD0", "REAL") == 1.5


def test_timer_bit_and_value_by_name() -> None:
    """plc['T37'] is the current value; read('T37', 'BIT') the timer bit."""
    plc = plcrt.load("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD     SM0.0\n"
                     "TON    T37, +2\nEND_ORGANIZATION_BLOCK\n", scan_ms=100)
    plc.scan(3)
    assert plc["T37"] == 2 and plc.read("T37", "BIT") == 1
    with pytest.raises(plcrt.PlcAddressError):
        plc.read("VW0", "BIT")
