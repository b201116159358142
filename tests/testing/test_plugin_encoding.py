"""The ``encoding=`` option of the ``plc`` marker and ``plc_factory``, and
the decoding of a marker's program with its tables in one encoding.  One
inner pytest run (a subprocess through the ``pytest11`` entry point) checks
them all."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

DATA = Path(__file__).resolve().parents[1] / "lang" / "data" / "encodings"


def test_marker_encoding_option(pytester: pytest.Pytester) -> None:
    for name in ("cz_table.awl", "cz_table.sym", "de_table.awl", "de_table.sym"):
        shutil.copy(DATA / name, pytester.path / name)
    pytester.makepyfile(test_enc="""\
import pytest

@pytest.mark.plc("cz_table.awl", symbols="cz_table.sym")
def test_table_and_program_share_the_encoding(plc):
    # alone the program reads as CP1252 ('Èerpadlo'); with its table, CP1250
    assert plc.plc.program.encoding == "cp1250"
    plc.set({"Čerpadlo": 1})
    plc.scan()
    assert plc.read("Q0.0") == 1

@pytest.mark.plc("de_table.awl", symbols="de_table.sym", encoding="gbk")
def test_forced_encoding(plc):
    assert plc.plc.program.encoding == "gbk"
    assert "Start_F鰎derband" in plc.plc.symbols.entries

def test_factory_encoding(plc_factory):
    h = plc_factory("de_table.awl", symbols="de_table.sym", encoding="cp1252")
    assert "Start_Förderband" in h.plc.symbols.entries

@pytest.mark.plc("de_table.awl", encoding="klingon")
def test_unknown_encoding(plc):
    pass

@pytest.mark.plc("de_table.awl", encoding=1252)
def test_encoding_not_a_name(plc):
    pass
""")
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "-p", "no:hypothesispytest")
    result.assert_outcomes(passed=3, errors=2)
    result.stdout.fnmatch_lines([
        "*test_unknown_encoding: @pytest.mark.plc: unknown encoding 'klingon'*",
        "*test_encoding_not_a_name: @pytest.mark.plc: encoding must be a name*",
    ])


def test_harness_load_encoding() -> None:
    """Harness.load passes encoding= on, for files and for a parsed program
    whose table is still a path; an unknown name is a PlcConfigError."""
    from plcrt import PlcConfigError
    from plcrt.engine.runtime import parse_sources
    from plcrt.testing import Harness

    awl, sym = DATA / "de_table.awl", DATA / "de_table.sym"
    h = Harness.load(awl, symbols=sym, encoding="gbk")
    assert "Start_F鰎derband" in h.plc.symbols.entries
    parsed = parse_sources(awl, encoding="gbk")
    h = Harness.load(parsed, symbols=sym, encoding="gbk")
    assert "Start_F鰎derband" in h.plc.symbols.entries
    with pytest.raises(PlcConfigError, match="unknown encoding"):
        Harness.load(parsed, symbols=sym, encoding="klingon")
