"""Encoding of export files (:mod:`plcrt.lang.encoding`): the sample corpus
in several languages, short comments, one encoding for a program and its
tables, forced encodings and the errors of files that do not decode."""

from __future__ import annotations

import codecs
from pathlib import Path

import pytest

import plcrt
from plcrt.errors import PlcConfigError, PlcSyntaxError
from plcrt.lang.encoding import (CANDIDATES, decode_bytes, decode_many, read_decoded,
                                 resolve_encoding)

DATA = Path(__file__).parent / "data" / "encodings"

# file -> (encoding decided, how, a string the decoded text must contain)
CORPUS = {
    "de_cp1252.awl": ("cp1252", "detected", "Endschalter prüfen: Tür geöffnet -> Übertemperatur"),
    "de_cp1252_short.awl": ("cp1252", "detected", "// Förderband"),
    "de_table.sym": ("cp1252", "detected", "Schütz des Förderbands"),
    "de_table.txt": ("cp1252", "detected", "Zähler für Störungen"),
    "fr_cp1252.awl": ("cp1252", "detected", "Contrôle du cœur de la machine à façon"),
    "pl_cp1250.awl": ("cp1250", "detected", "Wyłącznik krańcowy, załączenie silnika"),
    "cz_table.sym": ("cp1250", "detected", "tlak vody příliš nízký"),
    "ru_cp1251.awl": ("cp1251", "detected", "Аварийный останов, проверка датчика"),
    "zh_gbk.awl": ("gbk", "detected", "ORGANIZATION_BLOCK 主程序:OB1"),
    "zh_gb18030.awl": ("gb18030", "detected", "主程序 • 刘䶮的设备"),
    "zh_tw_cp950.awl": ("cp950", "detected", "馬達啟動，緊急停止按鈕"),
    "ja_cp932.awl": ("cp932", "detected", "モーター起動、非常停止ボタン"),
    "ko_cp949.awl": ("cp949", "detected", "모터 기동, 비상 정지 버튼"),
    "utf8.awl": ("utf-8", "utf-8", "TITLE=Förderband 主程序"),
    "utf8_bom.awl": ("utf-8", "bom", "TITLE=Förderband 主程序"),
    "utf16le_bom.awl": ("utf-16-le", "bom", "Запуск • メイン"),
    "utf16be_bom.awl": ("utf-16-be", "bom", "Запуск • メイン"),
    "utf16le.awl": ("utf-16-le", "utf-16 pattern", "// 电机启动"),
    "utf16be.awl": ("utf-16-be", "utf-16 pattern", "// 电机启动"),
}


@pytest.mark.parametrize("name", sorted(CORPUS))
def test_corpus_file_decodes_in_its_encoding(name: str) -> None:
    """Each sample decodes in the encoding it was written in, to its words."""
    encoding, how, words = CORPUS[name]
    decoded = read_decoded(DATA / name)
    assert (decoded.encoding, decoded.how) == (encoding, how)
    assert words in decoded.text
    assert not decoded.text.startswith("\ufeff")


@pytest.mark.parametrize("name", sorted(n for n in CORPUS if n.endswith(".awl")))
def test_corpus_program_parses(name: str) -> None:
    """Every sample program loads (the decoded text is a program, BOM and
    UTF-16 included)."""
    plc = plcrt.load(DATA / name)
    assert plc.program.pous[0].ident == "OB1"
    assert plc.program.encoding == CORPUS[name][0]


def test_confidence_of_the_corpus() -> None:
    """Unambiguous readings are confident; Korean read against GBK and
    French against CP1250 stay within the margin and are marked guesses."""
    low = {name for name in CORPUS if not read_decoded(DATA / name).confident}
    assert low == {"fr_cp1252.awl", "ko_cp949.awl"}


def ob1(comment: str) -> str:
    return (f"ORGANIZATION_BLOCK MAIN:OB1\r\nBEGIN\r\nNetwork 1 // {comment}\r\n"
            f"LD     I0.0\r\n=      Q0.0\r\nEND_ORGANIZATION_BLOCK\r\n")


# A one-comment program per phrase: the shortest texts, where a detector
# alone fails (charset-normalizer reads `Förderband` as HP Roman-8 and GBK
# reads it as `F鰎derband`).  These justify the scoring rule.
SHORT = [
    ("cp1252", p) for p in (
        "Förderband", "Zähler", "Tür zu", "Störung", "Größe", "Ventil über Druck",
        "Motor läuft", "Endschalter Öffner", "Straße", "Démarrage", "Arrêt",
        "Pièce présente", "Sécurité", "Contrôle", "Niveau élevé", "Válvula de presión",
        "Señal", "Temperatura alta 80 °C", "Pompa già avviata", "Ventilação")
] + [
    ("cp1250", p) for p in ("Przenośnik", "Ciśnienie", "Włącz silnik", "Zawór bezpieczeństwa",
                            "Teplota vysoká", "Nyomás")
] + [
    ("cp1251", p) for p in ("Пуск", "Стоп", "Насос", "Двигатель", "Авария", "Датчик уровня")
] + [
    ("gbk", p) for p in ("电机", "启动", "急停", "主程序", "温度报警", "输送带正转", "阀门打开")
] + [
    ("cp932", p) for p in ("起動", "停止", "モーター", "非常停止", "コンベア運転", "温度異常")
] + [
    ("cp1253", p) for p in ("Αντλία", "Κινητήρας")
]


@pytest.mark.parametrize(("encoding", "phrase"), SHORT)
def test_short_comment_decodes_right(encoding: str, phrase: str) -> None:
    """One short comment is enough to read it in the right code page (or one
    that gives the same text: Hungarian `Nyomás` is the same in CP1252)."""
    text = ob1(phrase)
    assert decode_bytes(text.encode(encoding), "p.awl").text == text


@pytest.mark.parametrize(("encoding", "phrase"), [
    ("cp1250", "Čerpadlo"), ("cp1250", "Spínač"),    # read as CP1252 `Èerpadlo`
    ("cp949", "모터"), ("cp949", "온도 경보"),        # read as common GBK hanzi
])
def test_ambiguous_short_comment_is_a_guess(encoding: str, phrase: str) -> None:
    """A word that two code pages read as plausible text is decided by the
    order of CANDIDATES (the more common one wins) and marked a guess."""
    decoded = decode_bytes(ob1(phrase).encode(encoding), "p.awl")
    assert not decoded.confident
    order = [c for c, _ in CANDIDATES]
    assert order.index(decoded.encoding) < order.index(encoding)


# --------------------------------------------------------------------------
# One encoding for a program and its tables
# --------------------------------------------------------------------------

def test_program_and_table_decode_together() -> None:
    """The Czech program alone reads as CP1252 (`Èerpadlo`), its table as
    CP1250; together both are CP1250, and the symbol is found."""
    awl, sym = DATA / "cz_table.awl", DATA / "cz_table.sym"
    assert read_decoded(awl).encoding == "cp1252"
    plc = plcrt.load(awl, symbols=sym)
    assert plc.program.encoding == "cp1250"
    assert list(plc.symbols.entries) == ["Čerpadlo"]
    plc.write("I0.0", 1)
    plc.scan()
    assert plc.read("Q0.0") == 1


def test_german_program_with_table_and_data_block() -> None:
    """Umlaut symbol names resolve and the data block loads."""
    plc = plcrt.load(DATA / "de_table.awl", symbols=DATA / "de_table.sym",
                     data=DATA / "de_table.txt")
    assert plc.program.encoding == "cp1252"
    assert plc.read("VW2") == 500
    plc.write("Start_Förderband", 1)
    plc.scan()
    assert plc.read("Förderband_Ein") == 1


def test_legacy_program_with_a_utf8_table(tmp_path: Path) -> None:
    """A CP1250 program whose one name alone reads as CP1252 (`Èerpadlo`)
    is read so that it has the names of its UTF-8 symbol table."""
    awl, sym = tmp_path / "p.awl", tmp_path / "p.sym"
    awl.write_bytes((DATA / "cz_table.awl").read_bytes())
    sym.write_text("Čerpadlo\tI0.0\tčerpadlo\r\n", encoding="utf-8")
    plc = plcrt.load(awl, symbols=sym)
    assert plc.program.encoding == "cp1250"
    plc.write("Čerpadlo", 1)
    plc.scan()
    assert plc.read("Q0.0") == 1


def test_files_no_one_encoding_reads_are_decoded_alone() -> None:
    """A UTF-8 program with a CP1251 table: each in its own encoding."""
    utf8 = "// Насос\n".encode("utf-8")
    cp1251 = "// Двигатель конвейера\n".encode("cp1251")
    found = decode_many([(utf8, "a.awl"), (cp1251, "a.sym")])
    assert [d.encoding for d in found] == ["utf-8", "cp1251"]
    assert found[1].text == "// Двигатель конвейера\n"


def test_forced_encoding_applies_to_all_files() -> None:
    """encoding= decodes every file with it, consistently: GBK reads the
    German names as hanzi in the program and the table alike."""
    plc = plcrt.load(DATA / "de_table.awl", symbols=DATA / "de_table.sym", encoding="gbk")
    assert plc.program.encoding == "gbk"
    assert "Start_F鰎derband" in plc.symbols.entries
    assert "Start_F鰎derband" in plc.program.source


# --------------------------------------------------------------------------
# Forced encodings, names, errors
# --------------------------------------------------------------------------

@pytest.mark.parametrize(("name", "codec"), [
    ("cp1252", "cp1252"), ("windows-1252", "cp1252"), ("936", "gbk"), ("GBK", "gbk"),
    ("shift_jis", "shift_jis"), ("UTF8", "utf-8"), ("utf-16le", "utf-16-le"),
    ("auto", None), ("", None), (None, None),
])
def test_resolve_encoding(name: str | None, codec: str | None) -> None:
    """Python's names and aliases, bare code page numbers, and auto."""
    assert resolve_encoding(name) == codec


@pytest.mark.parametrize("name", ["klingon", "hex", "rot13", "base64", 1252, b"cp1252"])
def test_unknown_encoding_is_a_config_error(name: object) -> None:
    """Unknown names and codecs that are not text encodings are refused."""
    with pytest.raises(PlcConfigError, match="encoding"):
        resolve_encoding(name)  # type: ignore[arg-type]


def test_load_refuses_unknown_encoding_even_for_text() -> None:
    with pytest.raises(PlcConfigError, match="unknown encoding 'klingon'"):
        plcrt.load(ob1("x"), encoding="klingon")


def test_forced_encoding_that_does_not_decode_names_the_first_bad_byte() -> None:
    """Russian CP1251 forced as UTF-8: the error is at the first Cyrillic
    letter (line 2, column 7), names the encoding and the byte."""
    with pytest.raises(PlcSyntaxError) as info:
        plcrt.load(DATA / "ru_cp1251.awl", encoding="utf-8")
    loc = info.value.loc
    assert (loc.file, loc.line, loc.column) == (str(DATA / "ru_cp1251.awl"), 2, 7)
    assert "does not decode as UTF-8: byte 0xCE" in info.value.message


def test_bad_byte_position_counts_characters_in_utf16() -> None:
    """Lines and columns count decoded characters, in UTF-16 as well."""
    data = codecs.BOM_UTF16_LE + "LD I0.0\r\n// ab".encode("utf-16-le") + b"\x00\xdc"
    with pytest.raises(PlcSyntaxError) as info:
        decode_bytes(data, "u.awl")
    assert (info.value.loc.line, info.value.loc.column) == (2, 6)
    assert "UTF-16-LE" in info.value.message


def test_bytes_no_code_page_reads_point_at_the_first_bad_utf8_byte() -> None:
    """Bytes invalid in UTF-8 and every candidate code page are an error at
    the first byte UTF-8 rejects, saying --encoding chooses one."""
    data = "LD I0.0\n// Zähler ".encode("utf-8") + b"\x80\n\x81\n\x98\n\xa0\n\xff\n"
    for codec, _ in CANDIDATES:
        with pytest.raises(UnicodeDecodeError):
            data.decode(codec)
    with pytest.raises(PlcSyntaxError) as info:
        decode_bytes(data, "x.awl")
    assert (info.value.loc.line, info.value.loc.column) == (2, 11)
    assert "byte 0x80" in info.value.message and "--encoding" in info.value.message


def test_nul_bytes_in_a_non_utf16_file() -> None:
    """A NUL in text that is not UTF-16 is reported at its position."""
    with pytest.raises(PlcSyntaxError, match="NUL byte") as info:
        decode_bytes(b"LD I0.0\n= Q0\x00.0\n", "n.awl")
    assert (info.value.loc.line, info.value.loc.column) == (2, 5)


def test_forced_encoding_drops_its_own_bom() -> None:
    """--encoding utf-8 on a file with a UTF-8 BOM: the mark is not text."""
    decoded = read_decoded(DATA / "utf8_bom.awl", "utf-8")
    assert decoded.text.startswith("ORGANIZATION_BLOCK")


def test_syntax_error_in_a_guessed_file_mentions_the_guess(tmp_path: Path) -> None:
    """A syntax error in a file decoded with low confidence carries a note
    naming the guess and --encoding; a confident decoding carries none."""
    bad = ob1("Čerpadlo").replace("=      Q0.0", "=      Q0.0 ;;")
    path = tmp_path / "cz.awl"
    path.write_bytes(bad.encode("cp1250"))
    with pytest.raises(PlcSyntaxError) as info:
        plcrt.load(path)
    notes = [d for d in info.value.diagnostics if d.severity == "note"]
    assert len(notes) == 1
    assert "decoded as CP1252, a guess" in notes[0].message
    assert "--encoding" in notes[0].message
    assert notes[0].loc == info.value.diagnostics[0].loc
    path.write_bytes(bad.encode("utf-8"))
    with pytest.raises(PlcSyntaxError) as info:
        plcrt.load(path)
    assert [d.severity for d in info.value.diagnostics] == ["error"]
