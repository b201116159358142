"""The lesson text of the panel: a small Markdown reader that turns the text
into a safe structure the page builds with ``textContent`` (never HTML).

Headings, paragraphs, bullet and numbered lists, fenced code blocks and
tables; inside them ``**bold**``, ``*italic*``, ``code`` and links.  A link
keeps its target only when it is ``http://`` or ``https://`` (the page
opens it in a new tab, ``rel="noopener noreferrer"``) or a relative link to
a file of the lesson's own folder (``lesson.awl``, served at
``/lesson/NAME``, see :mod:`plcrt.web.server`); any other link (``javascript:``,
``data:``, ``//host``, ``../elsewhere``) keeps only its words.

The structure, one dict per block::

    {"h": 2, "s": SPANS}          a heading (level 1..6)
    {"p": SPANS}                   a paragraph
    {"ul": [SPANS, ...]}           a bullet list ("ol": numbered, "start":
                                   its first number when not 1)
    {"pre": "text"}                a code block
    {"table": {"head": [SPANS, ...], "rows": [[SPANS, ...], ...]}}

and a span is ``{"t": text}`` with ``"b"``, ``"i"``, ``"code"`` (true) or
``"href"`` (the checked target) when they apply.  This module reads text
and returns data: it neither serves nor draws.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

#: characters of a lesson text read (the rest is cut, with a note)
MAX_CHARS = 100_000

Span = dict[str, Any]
Block = dict[str, Any]

_INLINE = re.compile(
    r"`(?P<code>[^`]+)`"
    r"|\*\*(?P<b>(?:(?!\*\*).)+)\*\*"
    r"|\*(?P<i>[^*\s](?:[^*]*[^*\s])?)\*"
    r"|\[(?P<lt>[^\]]+)\]\((?P<url>[^()\s]+)\)")
_ITEM = re.compile(r"^(\s*)([*+-]|\d{1,9}[.)])\s+(.*)$")
_RULE = re.compile(r"^\s*\|?[\s:|-]+\|?\s*$")
_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")


def link_target(url: str, local: Callable[[str], str | None] | None = None) -> str | None:
    """The target a link may keep: an ``http(s)://`` URL as written, a
    relative one as ``local`` maps it (None: the words only)."""
    low = url.lower()
    if low.startswith(("http://", "https://")) and len(url) > len("https://"):
        return url
    if _SCHEME.match(url) or url.startswith(("/", "\\")):
        return None
    return local(url) if local is not None else None


def inline(text: str, local: Callable[[str], str | None] | None = None,
           style: dict[str, Any] | None = None, depth: int = 0) -> list[Span]:
    """The spans of one line of text (emphasis nests at most 3 deep)."""
    style = style or {}
    out: list[Span] = []
    pos = 0

    def plain(t: str) -> None:
        if t:
            out.append({"t": t, **style})

    for m in _INLINE.finditer(text):
        plain(text[pos:m.start()])
        pos = m.end()
        if m.group("code") is not None:
            out.append({"t": m.group("code"), **style, "code": True})
        elif depth >= 3:
            plain(m.group(0))
        elif m.group("b") is not None:
            out += inline(m.group("b"), local, {**style, "b": True}, depth + 1)
        elif m.group("i") is not None:
            out += inline(m.group("i"), local, {**style, "i": True}, depth + 1)
        else:
            href = link_target(m.group("url"), local)
            more = {"href": href} if href is not None else {}
            out += inline(m.group("lt"), local, {**style, **more}, depth + 1)
    plain(text[pos:])
    return out


def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def parse(text: str, local: Callable[[str], str | None] | None = None) -> list[Block]:
    """The blocks of a Markdown text (see the module's docstring)."""
    cut = len(text) > MAX_CHARS
    lines = text[:MAX_CHARS].replace("\r\n", "\n").split("\n")
    blocks: list[Block] = []
    para: list[str] = []
    items: list[str] | None = None

    def flush() -> None:
        nonlocal items
        if para:
            blocks.append({"p": inline(" ".join(para), local)})
            para.clear()
        items = None

    i = 0
    while i < len(lines):
        line = lines[i]
        stripped = line.strip()
        if stripped.startswith("```"):
            indent = len(line) - len(line.lstrip())
            body = []
            i += 1
            while i < len(lines) and not lines[i].strip().startswith("```"):
                body.append(lines[i][indent:] if lines[i][:indent].isspace() else lines[i].strip())
                i += 1
            if para:
                flush()
            blocks.append({"pre": "\n".join(body)})
        elif stripped.startswith("|") and i + 1 < len(lines) and _RULE.match(lines[i + 1]) \
                and "-" in lines[i + 1]:
            flush()
            head = [inline(c, local) for c in _cells(line)]
            rows = []
            i += 2
            while i < len(lines) and lines[i].strip().startswith("|"):
                rows.append([inline(c, local) for c in _cells(lines[i])])
                i += 1
            blocks.append({"table": {"head": head, "rows": rows}})
            continue
        elif re.match(r"^#{1,6} ", line):
            flush()
            level = len(line) - len(line.lstrip("#"))
            blocks.append({"h": level, "s": inline(line[level:].strip(), local)})
        elif _ITEM.match(line):
            m = _ITEM.match(line)
            assert m is not None
            kind = "ul" if m.group(2) in "*+-" else "ol"
            if para:
                blocks.append({"p": inline(" ".join(para), local)})
                para.clear()
            if items is None or kind not in blocks[-1]:
                items = []
                blocks.append({kind: items})
                number = m.group(2)[:-1]
                if kind == "ol" and number != "1":   # a list split by a code block
                    blocks[-1]["start"] = int(number)
            items.append(m.group(3).strip())
        elif not stripped or stripped.startswith("<!--"):
            if para:
                blocks.append({"p": inline(" ".join(para), local)})
                para.clear()
            if not stripped and items is not None and not _continues(lines, i):
                items = None
        elif items is not None and line[:1].isspace():
            items[-1] += " " + stripped
        else:
            items = None
            para.append(stripped)
        i += 1
    flush()
    if cut:
        blocks.append({"p": [{"t": f"(the text is cut after {MAX_CHARS} characters)",
                              "i": True}]})
    for b in blocks:   # list items become spans once they are complete
        for kind in ("ul", "ol"):
            if kind in b:
                b[kind] = [inline(t, local) for t in b[kind]]
    return blocks


def _continues(lines: list[str], i: int) -> bool:
    """Whether the list goes on after the blank line ``i``: the next text is
    indented (more of the last item) or another item."""
    for line in lines[i + 1:]:
        if line.strip():
            return line[:1].isspace() or bool(_ITEM.match(line))
    return False


def plain_text(blocks: list[Block]) -> str:
    """The words of the blocks, one block a line (for tests and logs)."""
    def words(spans: list[Span]) -> str:
        return "".join(s["t"] for s in spans)
    out = []
    for b in blocks:
        if "pre" in b:
            out.append(b["pre"])
        elif "table" in b:
            for row in [b["table"]["head"], *b["table"]["rows"]]:
                out.append(" | ".join(words(c) for c in row))
        elif "h" in b:
            out.append(words(b["s"]))
        elif "p" in b:
            out.append(words(b["p"]))
        else:
            out += [words(s) for s in b.get("ul", b.get("ol", []))]
    return "\n".join(out)


__all__ = ["MAX_CHARS", "inline", "link_target", "parse", "plain_text"]
