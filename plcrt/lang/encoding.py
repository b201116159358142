"""Decide the text encoding of Micro/WIN export files and decode them.

STEP 7-Micro/WIN writes its exports (``.awl`` programs, symbol tables, data
blocks) in the Windows ANSI code page of the PC that made them: CP1252 on a
German, French or English PC, CP936 (GBK) on a Chinese one, CP1251, CP1250,
CP932 (Shift-JIS) and so on; newer tools write UTF-8 (with or without a
byte-order mark) and Notepad's "Unicode" is UTF-16.  The file itself does not
say which, so this module decides, in this order (docs/decisions.md,
"Encodings"):

1. an encoding the user gave (``--encoding``, ``encoding=``) is used as is;
2. a byte-order mark (UTF-8, UTF-16 LE/BE);
3. UTF-16 without a mark, recognised by its NUL bytes: STL is mostly ASCII,
   so every other byte of a UTF-16 export is zero;
4. pure ASCII, then strict UTF-8 (legacy text is practically never valid
   UTF-8 once it has a few non-ASCII bytes);
5. otherwise each Windows code page Micro/WIN may have written that decodes
   the bytes cleanly is scored on the lines that hold non-ASCII text (in STL
   that is comments, titles and symbol names; the mnemonics are ASCII): the
   mess ratio of charset-normalizer's detector, subtracted from an STL-aware
   plausibility of the characters for that code page's script (an umlaut
   inside a Latin word, a common GB2312 hanzi, a whole Cyrillic word).  The
   detector alone is weak on the few words a program has: it reads a German
   comment as HP Roman-8 or as Chinese; the plausibility settles those.

Several files of one program (its ``.awl`` files, symbol table and data
block) are decided together by :func:`decode_files`: one encoding that
decodes all of them cleanly is preferred, and a reading that has the names
of the files already decoded (a UTF-8 symbol table) scores more, so a symbol
name reads the same in the program and in its table.

This module reads and decodes bytes; it does not parse anything.
"""

from __future__ import annotations

import codecs
import re
import unicodedata
from dataclasses import dataclass
from pathlib import Path
from typing import NoReturn, Sequence

from ..errors import Diagnostic, PlcConfigError, PlcSyntaxError, SourceLoc
from ..safetext import printable
from .limits import file_limit, read_capped

__all__ = ["Decoded", "decode_bytes", "decode_files", "decode_many", "encoding_note",
           "read_bytes", "read_decoded", "resolve_encoding"]


@dataclass(frozen=True, slots=True)
class Decoded:
    """The text of one file and how its encoding was decided."""

    text: str
    encoding: str    #: Python codec name, e.g. "utf-8", "cp1252", "gbk", "utf-16-le"
    how: str         #: "given", "bom", "utf-16 pattern", "ascii", "utf-8", "detected"
    confident: bool  #: False for a guess between close candidates

    @property
    def label(self) -> str:
        """The encoding as users write it: ``CP1252``, ``GBK``, ``UTF-16-LE``."""
        return self.encoding.upper()


#: what an encoding must write and read back to be one STL can be in: the
#: printable ASCII characters, tab and line ends (mnemonics, operands,
#: punctuation of every export)
_STL_SAMPLE = "".join(map(chr, range(32, 127))) + "\t\r\n"


def resolve_encoding(name: str | None) -> str | None:
    """Check an encoding name given by the user and return its codec name.

    ``None``, ``""`` and ``"auto"`` mean "detect".  A bare code page number
    (``936``, ``1252``) is the Windows code page of that number.  Raises
    :class:`PlcConfigError` for a name Python does not know as a text
    encoding, and for one that cannot write and read back the characters
    of STL (``punycode``, ``idna``, ``utf-7``, ``undefined``: they fail or
    mangle on any program).
    """
    if name is None:
        return None
    if not isinstance(name, str):
        raise PlcConfigError(f"encoding must be a name such as 'cp1252', 'gbk' or 'utf-8', "
                             f"got {type(name).__name__} {printable(repr(name))[:40]}")
    key = name.strip()
    if key.lower() in ("", "auto"):
        return None
    if key.isdigit():
        key = "cp" + key
    shown = printable(name)[:40]
    try:
        # str.encode accepts text encodings only (not hex, base64, rot13 ...)
        "".encode(key)
        codec = codecs.lookup(key).name
    except (LookupError, ValueError):
        # ValueError: a NUL in the name; UnicodeError (a ValueError): a
        # codec that refuses everything ("undefined")
        raise PlcConfigError(f"unknown encoding {shown!r}; give a name such as cp1252, "
                             f"gbk, gb18030, cp1251, cp932, utf-8 or utf-16") from None
    try:
        data = _STL_SAMPLE.encode(codec)
        # a file's beginning is the beginning of its bytes: not so for
        # punycode, which moves what it encodes to the end
        fits = data.decode(codec) == _STL_SAMPLE and all(
            data.startswith(_STL_SAMPLE[:k].encode(codec)) for k in (1, 16, 64))
    except (UnicodeError, ValueError):
        fits = False
    if not fits:
        raise PlcConfigError(f"encoding {shown!r} cannot hold the characters of STL (letters, "
                             f"digits, punctuation and line ends as Micro/WIN writes them); "
                             f"give a code page or a Unicode encoding such as cp1252, gbk, "
                             f"utf-8 or utf-16")
    return codec


def read_bytes(path: str | Path, max_bytes: int | None = None) -> bytes:
    """The bytes of a regular file, at most ``max_bytes`` (default: the
    limit of :mod:`plcrt.lang.limits`); :class:`PlcSyntaxError` naming it
    if it is unreadable, not a regular file or too large."""
    return read_capped(path, file_limit() if max_bytes is None else max_bytes)


def read_decoded(path: str | Path, encoding: str | None = None,
                 max_bytes: int | None = None) -> Decoded:
    """Read and decode one file (see :func:`decode_bytes`)."""
    return decode_bytes(read_bytes(path, max_bytes), str(path), encoding)


def decode_files(paths: Sequence[str | Path], encoding: str | None = None,
                 max_bytes: int | None = None) -> list[Decoded]:
    """Read and decode the files of one program with one encoding where possible.

    Files with a byte-order mark, UTF-16, pure-ASCII and UTF-8 files are
    decided alone.  The others are decoded with the one encoding that reads
    all of them cleanly and scores best over their text together; only if no
    encoding reads them all is each decided alone.  Either way a reading
    that has the non-ASCII words of the files decided alone scores more.
    """
    return decode_many([(read_bytes(p, max_bytes), str(p)) for p in paths], encoding)


def decode_many(items: Sequence[tuple[bytes, str]],
                encoding: str | None = None) -> list[Decoded]:
    """:func:`decode_files` for bytes already read: ``(data, file name)`` pairs."""
    codec = resolve_encoding(encoding)
    if codec is not None:
        return [decode_bytes(data, name, codec) for data, name in items]
    fixed: dict[int, Decoded] = {}
    legacy: list[int] = []
    for i, (data, name) in enumerate(items):
        d = _decode_unambiguous(data, name)
        if d is None:
            legacy.append(i)
        else:
            fixed[i] = d
    # the non-ASCII words of the files already decoded (a UTF-8 symbol
    # table): a reading of the others that has them is the right one
    context = frozenset(w for d in fixed.values() for w in _words(d.text))
    if len(legacy) > 1:
        joint = _best_candidate([items[i][0] for i in legacy], context)
        if joint is not None:
            codec, confident = joint
            for i in legacy:
                fixed[i] = Decoded(items[i][0].decode(codec), codec, "detected", confident)
    return [fixed[i] if i in fixed else _detect(*items[i], context)
            for i in range(len(items))]


def decode_bytes(data: bytes, file: str, encoding: str | None = None) -> Decoded:
    """Decode the bytes of one file.

    With ``encoding`` given the bytes must decode cleanly in it (a byte-order
    mark of that encoding is dropped).  Without, the encoding is detected as
    the module docstring describes.  Raises :class:`PlcSyntaxError` at the
    line and column of the first byte that does not decode, naming the
    encoding, or of a NUL byte in a file that is not UTF-16.
    """
    codec = resolve_encoding(encoding)
    if codec is not None:
        return _checked(data, file, _strip_bom(data, codec), codec, "given", True)
    return _detect(data, file, frozenset())


def _detect(data: bytes, file: str, context: frozenset[str]) -> Decoded:
    found = _decode_unambiguous(data, file)
    if found is not None:
        return found
    best = _best_candidate([data], context)
    if best is None:
        # Nothing reads it: the most likely intent is UTF-8 with a few bytes
        # from elsewhere pasted in, so point at the first byte UTF-8 rejects.
        _raise_undecodable(data, file, "utf-8", note="; no Windows code page that "
                           "Micro/WIN writes reads it cleanly either: pass --encoding "
                           "(encoding=) to choose one")
    codec, confident = best
    return _checked(data, file, data, codec, "detected", confident)


def encoding_note(decoded: Decoded | None, loc: SourceLoc) -> Diagnostic | None:
    """A note for the syntax errors of a file whose encoding was guessed
    (None when it was not); ``loc`` is the first error's, so the note
    follows it."""
    if decoded is None or decoded.confident:
        return None
    return Diagnostic("note", f"the file was decoded as {decoded.label}, a guess; if its "
                      f"comments or names look wrong, pass --encoding (encoding=) with the "
                      f"code page of the PC that exported it", loc, "encoding")


# --------------------------------------------------------------------------
# The unambiguous cases: BOM, UTF-16 pattern, ASCII, UTF-8
# --------------------------------------------------------------------------

_BOMS = ((codecs.BOM_UTF8, "utf-8"), (codecs.BOM_UTF16_LE, "utf-16-le"),
         (codecs.BOM_UTF16_BE, "utf-16-be"))


def _strip_bom(data: bytes, codec: str) -> bytes:
    # ("utf-16" and "utf-8-sig" consume their mark themselves)
    for bom, name in _BOMS:
        if codec == name and data.startswith(bom):
            return data[len(bom):]
    return data


def _decode_unambiguous(data: bytes, file: str) -> Decoded | None:
    for bom, codec in _BOMS:
        if data.startswith(bom):
            return _checked(data, file, data[len(bom):], codec, "bom", True)
    codec = _utf16_pattern(data)
    if codec is not None:
        return _checked(data, file, data, codec, "utf-16 pattern", True)
    if data.isascii():
        return _checked(data, file, data, "ascii", "ascii", True)
    try:
        return _no_nul(Decoded(data.decode("utf-8"), "utf-8", "utf-8", True), file)
    except UnicodeDecodeError:
        return None


def _utf16_pattern(data: bytes) -> str | None:
    """``utf-16-le``/``-be`` for BOM-less UTF-16 of mostly-ASCII text.

    In UTF-16 every ASCII character has a zero high byte; STL is mostly
    ASCII, so at least a third of one byte lane is NUL while the other lane
    has (almost) none.  Text in an 8-bit encoding has no NUL bytes at all.
    """
    half = len(data) // 2
    if half < 2:
        return None
    even, odd = data[0::2].count(0), data[1::2].count(0)
    if odd >= half / 3 and even <= half / 50:
        return "utf-16-le"
    if even >= half / 3 and odd <= half / 50:
        return "utf-16-be"
    return None


def _checked(raw: bytes, file: str, data: bytes, codec: str, how: str,
             confident: bool) -> Decoded:
    """Decode strictly; a bad byte is a syntax error at its position."""
    try:
        text = data.decode(codec)
    except UnicodeDecodeError as exc:
        _raise_undecodable(data, file, codec, exc, offset=len(raw) - len(data))
    except UnicodeError as exc:
        # a codec that fails without saying where (punycode and the like
        # pass resolve_encoding's sample, but not every text)
        raise PlcSyntaxError(f"the file does not decode as {codec.upper()}: "
                             f"{printable(str(exc))[:120]}", SourceLoc(file, 1, 1)) from None
    return _no_nul(Decoded(text, codec, how, confident), file)


def _no_nul(decoded: Decoded, file: str) -> Decoded:
    at = decoded.text.find("\0")
    if at >= 0:
        line, column = _position(decoded.text[:at])
        raise PlcSyntaxError(
            f"the file has a NUL byte (decoded as {decoded.label}): it is not a text export, "
            f"or it is UTF-16 that could not be recognised (pass --encoding utf-16-le or "
            f"utf-16-be)", SourceLoc(file, line, column))
    return decoded


def _raise_undecodable(data: bytes, file: str, codec: str,
                       exc: UnicodeDecodeError | None = None, *, offset: int = 0,
                       note: str = "") -> NoReturn:
    if exc is None:
        try:
            data.decode(codec)
        except UnicodeDecodeError as e:
            exc = e
    assert exc is not None
    start = exc.start
    line, column = _position(data[:start].decode(codec, errors="replace"))
    bad = " ".join(f"0x{b:02X}" for b in data[start:min(exc.end, start + 4)])
    raise PlcSyntaxError(
        f"the file does not decode as {codec.upper()}: byte {bad} (file offset "
        f"{start + offset}) is not valid in that encoding{note}",
        SourceLoc(file, line, column))


def _position(prefix: str) -> tuple[int, int]:
    """(line, column) just after ``prefix``, counting lines as the parser
    does (CRLF, CR and LF each end one line)."""
    lines = re.split(r"\r\n|\r|\n", prefix)
    return len(lines), len(lines[-1]) + 1


# --------------------------------------------------------------------------
# Legacy code pages: detector plus STL-aware plausibility
# --------------------------------------------------------------------------

#: Windows ANSI code pages Micro/WIN may have written, in the order preferred
#: when two read the bytes as the same text, with the script family whose
#: characters make a reading plausible (see :func:`_weight`).
CANDIDATES: tuple[tuple[str, str], ...] = (
    ("cp1252", "latin"),     # Western Europe and the Americas
    ("gbk", "han"),          # Simplified Chinese (CP936)
    ("gb18030", "han"),      # Simplified Chinese, characters beyond GBK
    ("cp1250", "latin"),     # Central Europe
    ("cp1251", "cyrillic"),
    ("cp932", "japanese"),   # Shift-JIS
    ("cp949", "hangul"),     # Korean
    ("cp950", "big5"),       # Traditional Chinese
    ("cp1253", "greek"),
    ("cp1254", "latin"),     # Turkish
    ("cp1257", "latin"),     # Baltic
)

#: Size of the text scored (non-ASCII lines, evenly spread over the files).
SAMPLE_BYTES = 16384
#: Weight of the words a reading shares with the program's other files.
SHARED = 0.5
#: Scores this close count as equal.
TIE = 0.05
#: A guess is confident when it scores at least this much ...
CONFIDENT_SCORE = 0.6
#: ... and at least this much more than the next candidate.
CONFIDENT_MARGIN = 0.2

#: Letters whose next letter spelling fixes: French œ comes before u or i
#: (cœur, œil), Spanish ñ before a vowel (señal, año).
_FOLLOWERS = {"œ": "uiUI", "Œ": "uiUI", "ñ": "aeiouáéíóú", "Ñ": "AEIOUaeiou"}
#: Typographic signs a comment in a Latin, Cyrillic or Greek code page uses
#: alone (``80 °C``, ``„Tür“``, ``5 €``, ``№ 3``); others are mojibake-ish.
_SIGNS = frozenset("°µ€–—„“”‘’‚«»·×²³§©®™…\u00a0№")


def _best_candidate(blobs: Sequence[bytes],
                    context: frozenset[str] = frozenset()) -> tuple[str, bool] | None:
    """(codec, confident) for the code page that reads every blob cleanly
    and scores best on their non-ASCII lines together, or None.  A reading
    whose non-ASCII words are among the ``context`` words (those of the
    program's other, already decoded files) scores up to SHARED more."""
    from charset_normalizer.md import mess_ratio

    lines = [line for data in blobs for line in data.splitlines() if not line.isascii()]
    # perf: the scoring is pure Python; lines spread over the files, about
    # SAMPLE_BYTES of them, decide as well as all of them
    step = -(-sum(map(len, lines)) // SAMPLE_BYTES)
    sample = b"\n".join(lines[::max(step, 1)])
    seen: set[str] = set()
    scored: list[tuple[float, str]] = []
    for codec, family in CANDIDATES:
        try:
            for data in blobs:
                data.decode(codec)
            text = sample.decode(codec)
        except UnicodeDecodeError:
            continue
        if text in seen:
            continue  # reads the same as a preferred code page
        seen.add(text)
        # charset-normalizer's mess detector: 0 for clean text, more for
        # mojibake (odd symbol runs, suspicious accents, mixed scripts)
        score = _plausibility(text, codec, family) - mess_ratio(text, maximum_threshold=1.0)
        if context:
            words = _words(text)
            score += SHARED * len(words & context) / max(len(words), 1)
        scored.append((score, codec))
    if not scored:
        return None
    # Scores within TIE of the best are a tie, settled by the order of
    # CANDIDATES (the more common code page wins).
    top = max(score for score, _ in scored)
    chosen = next(i for i, (score, _) in enumerate(scored) if score >= top - TIE)
    score, codec = scored[chosen]
    others = [s for i, (s, _) in enumerate(scored) if i != chosen]
    confident = score >= CONFIDENT_SCORE and score - max(others, default=-1.0) >= CONFIDENT_MARGIN
    return codec, confident


def _words(text: str) -> set[str]:
    """The words of ``text`` that have a non-ASCII letter (names, comments)."""
    return {w for w in _WORD.findall(text) if not w.isascii()}


_WORD = re.compile(r"\w+")
_ALPHABETIC = ("latin", "cyrillic", "greek")
_RUN = re.compile(r"[^\x00-\x7f]+")
_ASCII_ALNUM = re.compile(r"[A-Za-z0-9]")


def _plausibility(text: str, codec: str, family: str) -> float:
    """Mean weight of the non-ASCII characters of ``text`` read in ``codec``
    of script ``family`` (1.0: what such a PC writes; 0: never)."""
    total = 0.0
    count = 0
    alphabet = _best_alphabet(text, codec)
    for m in _RUN.finditer(text):
        run = m.group()
        start, end = m.start(), m.end()
        # an ASCII letter right before or after the run: the word mixes both
        in_ascii_word = bool(start and _ASCII_ALNUM.match(text, start - 1)
                             or _ASCII_ALNUM.match(text, end))
        for k, c in enumerate(run):
            w = _weight(c, family, len(run), in_ascii_word, text[start + k + 1:start + k + 2])
            if alphabet is not None and c.isalpha() and c.lower()[0] not in alphabet:
                w *= 0.4  # no one language of the code page writes all these letters
            if k and c.isupper() and run[k - 1].islower() and family in _ALPHABETIC:
                w *= 0.5  # a capital after a small letter inside a word: "ЦчіМРт"
            total += w
        count += len(run)
    return total / count if count else 1.0


def _weight(c: str, family: str, run: int, in_ascii_word: bool, after: str) -> float:
    """How plausible character ``c`` is in text of ``family``.

    ``run`` is the length of the run of non-ASCII characters it is in,
    ``in_ascii_word`` whether its word also has ASCII letters, ``after`` the
    character that follows it.  The rules follow how each script is
    written: Latin languages put one or two accented letters inside
    mostly-ASCII words (``Förderband``, ``élevée``), Cyrillic and Greek
    words are non-ASCII throughout, Chinese text uses the common hanzi of
    GB2312 almost exclusively, Japanese mixes kana and the JIS X 0208 kanji.
    Misreadings break these patterns: CP1252 read as GBK gives rare hanzi,
    GBK read as CP1252 gives long runs of accented letters and signs, CP1252
    read as CP1251 gives Cyrillic letters inside Latin words.
    """
    cat = unicodedata.category(c)
    if cat[0] == "C":     # controls, private use, unassigned
        return 0.0
    name = unicodedata.name(c, "")
    if cat[0] != "L":
        if family in _ALPHABETIC:
            return 0.9 if c in _SIGNS and run == 1 else 0.1
        # CJK punctuation and full-width forms belong to CJK text
        return 0.8 if ("\u3000" <= c <= "\u303f" or "\uff00" <= c <= "\uffef") else 0.2
    if family == "latin":
        if not name.startswith("LATIN"):
            return 0.1
        if run > 2:
            return 0.25
        follow = _FOLLOWERS.get(c)
        return 1.0 if follow is None or (after and after in follow) else 0.4
    if family in ("cyrillic", "greek"):
        if not name.startswith(family.upper()):
            return 0.1
        return 0.2 if in_ascii_word else 1.0
    if family == "han":
        return _hanzi(c) if "CJK" in name else 0.2
    if family == "japanese":
        if name.startswith("HALFWIDTH KATAKANA"):
            # old Japanese tools write kana half-width, but in words of
            # several letters, not as one sign between ASCII (``80 °C``)
            return 0.5 if run > 1 else 0.2
        if name.startswith(("HIRAGANA", "KATAKANA")):
            return 1.0
        return _in(c, "shift_jis", 1.0, 0.4) if "CJK" in name else 0.2
    if family == "hangul":
        # KS X 1001 (both bytes >= 0xA1) has the 2350 common syllables;
        # hanja are rare in Korean comments today
        if name.startswith("HANGUL"):
            return 1.0 if _trail(c, "cp949") >= 0xA1 else 0.3
        return 0.4 if "CJK" in name else 0.2
    if family == "big5":
        # level 1 (lead bytes 0xA4-0xC6) has the 5401 common characters;
        # Traditional Chinese is the least common reading of the two
        return (0.8 if _lead(c, "cp950") < 0xC7 else 0.4) if "CJK" in name else 0.2
    return 0.1


#: The accented letters of the languages written in each Latin code page.
#: One language must account for a text's letters: Czech read as CP1252
#: gives è, ø and š together, which no Western language writes.
_WESTERN = ("äöüß", "àâæçéèêëîïôœùûüÿ", "áéíóúüñ", "àèéìíîòóùú", "áâãàçéêíóôõú",
            "éëïóöü", "æøåé", "åäöé")
LATIN_LANGUAGES: dict[str, tuple[str, ...]] = {
    "cp1252": _WESTERN,
    "cp1250": ("ąćęłńóśźż", "áčďéěíňóřšťúůýž", "áäčďéíĺľňóôŕšťúýž", "áéíóöőúüű",
               "čšž", "čćđšž", "ăâîşţ", "äöüß"),
    "cp1254": ("çğıöşüâîû", *_WESTERN),
    "cp1257": ("ąčęėįšųūž", "āčēģīķļņšūž", "äõöüšž", "äöüß"),
}


def _best_alphabet(text: str, codec: str) -> str | None:
    """The alphabet of ``codec``'s languages that holds most of the
    non-ASCII letters of ``text`` (None for a non-Latin code page)."""
    languages = LATIN_LANGUAGES.get(codec)
    if languages is None:
        return None
    letters = [c.lower()[0] for c in text if not c.isascii() and c.isalpha()]
    return max(languages, key=lambda a: sum(c in a for c in letters))


def _hanzi(c: str) -> float:
    """Weight of a hanzi: GB2312 level 1 (lead bytes 0xB0-0xD7, the 3755
    common characters) 1.0, level 2 (0xD8-0xF7, 3008 rarer ones) 0.6, any
    other (GBK and GB18030 additions) 0.4."""
    lead = _lead(c, "gb2312")
    return 1.0 if lead < 0xD8 else 0.6 if lead < 0x100 else 0.4


def _lead(c: str, codec: str) -> int:
    """First byte of ``c`` in ``codec`` (0x100 if it has none)."""
    try:
        return c.encode(codec)[0]
    except UnicodeEncodeError:
        return 0x100


def _trail(c: str, codec: str) -> int:
    """Last byte of ``c`` in ``codec`` (0 if it has none)."""
    try:
        return c.encode(codec)[-1]
    except UnicodeEncodeError:
        return 0


def _in(c: str, codec: str, yes: float, no: float) -> float:
    """``yes`` if ``c`` is in the (smaller, common-character) set ``codec``."""
    try:
        c.encode(codec)
    except UnicodeEncodeError:
        return no
    return yes
