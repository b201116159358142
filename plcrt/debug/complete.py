"""Tab completion for the debugger's prompt.

:func:`complete` is a pure function: given the line typed so far and a
:class:`Vocabulary` (the words a session knows), it returns the candidates
for the word under the cursor: command names first, then what the command
takes: networks for ``break``/``show``/``clear`` (``OB1/3``, ``SBR0/1``,
``SCALE/2``), breakpoints for ``delete``, addresses and symbols of the
program for ``watch``/``print``/``set``/``force``/``pulse``/``trace``/
``run until``, area prefixes (``I``, ``QB``, ``VW``, ``SM`` ...), the
``:REAL``/``:BIT`` suffixes, and command names for ``help``.

:func:`vocabulary` collects those words from a
:class:`~plcrt.debug.session.Session`; :class:`ReadlineCompleter` is the
small adapter ``readline.set_completer`` wants, installed by
:mod:`plcrt.debug.cli` on a terminal only.  Nothing here runs a scan or
changes the session.  Words from the program (symbol names) that would
not print as themselves on a terminal are never offered.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ..safetext import printable
from ..trace.recorder import DRIVE_QUANTITIES
from .commands import COMMANDS, lookup

if TYPE_CHECKING:
    from .session import Session

#: the areas and access widths an address may start with (S7-200 System
#: Manual, chapter 4, "Addressing the memory areas"): what ``V`` completes to
AREA_PREFIXES = (
    "I", "IB", "IW", "ID", "Q", "QB", "QW", "QD", "M", "MB", "MW", "MD",
    "V", "VB", "VW", "VD", "SM", "SMB", "SMW", "SMD", "S", "SB", "SW", "SD",
    "AIW", "AQW", "AC", "T", "C", "HC",
)

#: read suffixes: ``VD4:REAL`` reads a float, ``T37:BIT`` the timer bit
SUFFIXES = (":REAL", ":BIT")

#: an operand of the program that is a direct address (or a timer/counter)
_ADDRESS = re.compile(r"(?:SM|AI|AQ|AC|HC|[IQMVSLTC])[BWD]?\d+(?:\.\d)?", re.I)

#: commands whose words are addresses, symbols and signals
_ADDRESS_COMMANDS = {"watch", "print", "set", "force", "pulse", "unwatch", "unforce", "trace"}
#: commands whose words are networks
_NETWORK_COMMANDS = {"break", "show", "clear"}


@dataclass(frozen=True)
class Vocabulary:
    """The words completion draws from."""

    commands: tuple[str, ...] = ()
    #: every network as a breakpoint names it: OB1/1, SBR0/2, SCALE/2
    networks: tuple[str, ...] = ()
    #: direct addresses the program uses (I0.0, VW100, T37, C0)
    addresses: tuple[str, ...] = ()
    symbols: tuple[str, ...] = ()
    #: other trace signals (axis0.0.speed ... with a plant)
    signals: tuple[str, ...] = ()
    #: the session's state of the moment
    breakpoints: tuple[str, ...] = ()
    watched: tuple[str, ...] = ()
    forced: tuple[str, ...] = ()
    areas: tuple[str, ...] = field(default=AREA_PREFIXES)


def complete(line: str, vocab: Vocabulary) -> list[str]:
    """Candidates for the last word of ``line`` (the text before the cursor),
    sorted, without duplicates; an empty list when there is nothing to offer."""
    words = line.split()
    if not line or line[-1].isspace():
        words.append("")
    word = words[-1]
    if len(words) == 1:
        return _matching(word, vocab.commands)
    command = _command(words[0], vocab.commands)
    previous = [w.lower() for w in words[1:-1]]
    if command == "help":
        return _matching(word, vocab.commands) if not previous else []
    if command in _NETWORK_COMMANDS:
        return _matching(word, vocab.networks)
    if command == "delete":
        return _matching(word, ("all", *vocab.breakpoints))
    if command == "run":
        if not previous:
            return _matching(word, ("until",))
        if previous[0] != "until":
            return []
        if previous[-1] == "timeout":
            return []
        return _address(word, vocab) + (_matching(word, ("not", "timeout"))
                                        if word else [])
    if command not in _ADDRESS_COMMANDS:
        return []
    if command == "set" and "=" in word:
        return []                       # the value after ADDR= is the user's
    if command in ("force", "pulse") and previous:
        return []                       # force ADDR VALUE, pulse ADDR SCANS
    if command == "unwatch":
        return _matching(word, ("all", *vocab.watched))
    if command == "unforce":
        return _matching(word, ("all", *vocab.forced))
    if command == "trace":
        extra = vocab.signals + (("stop", "clear") if not previous else ())
        return sorted(set(_address(word, vocab) + _matching(word, extra)))
    return _address(word, vocab)


def _address(word: str, vocab: Vocabulary) -> list[str]:
    """Addresses, symbols and area prefixes; after ``ADDR:`` the suffixes."""
    base, colon, _ = word.partition(":")
    if colon:
        # T37:BIT is the timer bit; :REAL reads a double word as a float
        suffixes = ((":BIT",) if re.fullmatch(r"[TC]\d+", base, re.I) else
                    (":REAL",) if re.fullmatch(r"[A-Z]+D\d+", base, re.I) else SUFFIXES)
        return _matching(word, [base + s for s in suffixes])
    return sorted(set(_matching(word, vocab.addresses) + _matching(word, vocab.symbols)
                      + _matching(word, vocab.areas)))


def _matching(word: str, candidates: Any) -> list[str]:
    """The candidates that start with ``word``, ignoring case (``vw1`` is
    ``VW1``)."""
    low = word.lower()
    return sorted({c for c in candidates if c.lower().startswith(low)})


def _command(word: str, commands: tuple[str, ...]) -> str | None:
    """The command a first word names (its short forms included)."""
    cmd = lookup(word)
    if cmd is not None:
        return cmd.name
    return word.lower() if word.lower() in commands else None


def _offerable(name: str) -> bool:
    """A word from the program that prints as itself, in one word."""
    return bool(name) and printable(name) == name and not any(c.isspace() for c in name)


def vocabulary(session: Session) -> Vocabulary:
    """The words of a session: its program's networks, addresses and
    symbols, and the breakpoints, watches and forces of the moment."""
    plc = session.plc
    networks: list[str] = []
    for pou in plc.program.pous:
        names = {pou.ident}
        if _offerable(pou.name):
            names.add(pou.name)
        for net in pou.networks:
            networks += [f"{name}/{net.number}" for name in sorted(names)]
    addresses = {op.text.upper() for pou in plc.program.pous for net in pou.networks
                 for insn in net.insns for op in insn.operands
                 if _ADDRESS.fullmatch(op.text)}
    symbols = tuple(n for n in (plc.symbols.entries if plc.symbols is not None else ())
                    if _offerable(n))
    signals = tuple(f"axis{a['slot']}.{a['axis']}.{kind}" for a in plc.axes()
                    for kind in ("position", "mechanical", "speed"))
    signals += tuple(f"drive{d.node}.{kind}" for d in plc.drives() for kind in DRIVE_QUANTITIES)
    return Vocabulary(
        commands=tuple(COMMANDS),
        networks=tuple(networks),
        addresses=tuple(sorted(addresses)),
        symbols=symbols,
        signals=signals,
        breakpoints=tuple(session.coverage.networks[k].name for k in sorted(session._breaks)),
        watched=tuple(w.spec for w in session._watches if _offerable(w.spec)),
        forced=tuple(k for k in plc.forces if _offerable(k)),
    )


class ReadlineCompleter:
    """``readline.set_completer`` glue: the candidates for the line buffer
    up to the cursor, one per ``state``.  The completer's word delimiters
    must be blanks only (``OB1/3``, ``VD4:REAL`` are one word)."""

    DELIMITERS = " \t\n"

    def __init__(self, session: Session, readline: Any) -> None:
        self.session = session
        self.readline = readline
        self._matches: list[str] = []

    def __call__(self, text: str, state: int) -> str | None:
        if state == 0:
            line = self.readline.get_line_buffer()[:self.readline.get_endidx()]
            try:
                self._matches = complete(line, vocabulary(self.session))
            except Exception:  # noqa: BLE001 - readline swallows errors; offer nothing
                self._matches = []
        return self._matches[state] if state < len(self._matches) else None


__all__ = ["AREA_PREFIXES", "ReadlineCompleter", "SUFFIXES", "Vocabulary", "complete",
           "vocabulary"]
