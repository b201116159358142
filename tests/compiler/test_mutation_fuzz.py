"""Grammar-aware mutation test of the load path: mutated sample programs are
refused with a :class:`plcrt.PlcError` or load, scan and fork; nothing else
ever escapes.

The mutants start from the sample programs (``programs/``, ``examples/``)
and the real-file corpus (``../shared/corpus``, skipped when absent) and
change what a program can get wrong: operands of every kind in every
position (bit, byte, word and double-word addresses of every area,
constants of every type, pointers, indirect and local operands, symbols),
constants where addresses go, huge numbers, every mnemonic with the
operands of another, unbalanced logic stacks, a subroutine calling itself,
lines deleted or doubled, networks cut short.  Each mutant is loaded with
the Python backend, every :data:`NATIVE_EVERY`-th also with the native one;
a mutant that loads runs a few scans and is forked.

What it is not: a test of what a program computes (the two backends are
compared elsewhere); a mutant only has to end in a ``PlcError`` or run.

Deterministic: mutant *i* is drawn from ``random.Random(f"{seed}:{i}")``,
so a failure names the one mutant to look at.  ``PLCRT_FUZZ_MUTANTS``
(default :data:`DEFAULT_MUTANTS`) says how many; ``PLCRT_FUZZ_SEED`` draws
another set.
"""

from __future__ import annotations

import os
import random
import re
import traceback
from dataclasses import dataclass
from pathlib import Path

import pytest

import plcrt
from plcrt.isa.registry import REGISTRY, load_families
from test_operand_kinds import TYPICAL  # an operand that fits each role

ROOT = Path(__file__).resolve().parents[2]
CORPUS = ROOT.parent / "shared" / "corpus"

#: mutants per run of the suite (a few seconds); scale with PLCRT_FUZZ_MUTANTS
DEFAULT_MUTANTS = 160
MUTANTS = int(os.environ.get("PLCRT_FUZZ_MUTANTS", DEFAULT_MUTANTS))
SEED = os.environ.get("PLCRT_FUZZ_SEED", "plcrt")
#: the mutants are split over this many tests (spread by pytest -n)
CHUNKS = 4
#: every NATIVE_EVERY-th mutant is also loaded with the native backend
NATIVE_EVERY = 6
SCANS = 3

load_families()
MNEMONICS = sorted(REGISTRY)

# -- operands of every kind ----------------------------------------------------

BITS = ["I0.0", "Q0.7", "M31.7", "V100.3", "SM0.0", "SM0.1", "SM1.0", "SM30.0", "S0.1",
        "L0.0", "L63.7", "T37", "C5", "I15.7", "V10239.7", "V10240.0", "I0.8", "Q16.0"]
BYTES = ["IB0", "QB0", "MB0", "VB100", "VB0", "SMB0", "SMB30", "SB0", "LB0", "LB63", "AC0",
         "AC3", "VB10239", "VB10240", "HC0", "AC4"]
WORDS = ["IW0", "QW0", "MW0", "VW100", "SMW22", "SW0", "LW0", "LW62", "AIW0", "AQW0",
         "AIW1", "T37", "C5", "T255", "C256", "VW10238", "VW10239"]
DWORDS = ["ID0", "QD0", "MD0", "VD100", "SMD0", "SD0", "LD0", "LD60", "HC0", "HC5", "AC1",
          "VD10236", "VD10237", "AID0"]
INTS = ["0", "1", "-1", "+255", "256", "-129", "-32768", "32767", "65535", "65536",
        "2147483647", "-2147483648", "4294967295", "4294967296", "+99999999999",
        str(10 ** 30), "-" + str(10 ** 30), "9" * 40, "16#FF", "16#FFFF", "16#FFFFFFFF",
        "16#1_0000_0000", "2#1010", "2#" + "1" * 70, "TRUE", "OFF"]
REALS = ["1.5", "-0.0", "0.0", "3.402823E+38", "3.5E+38", "-1.0E+39", "1.0E-45",
         "1.0E-50", "1E+308", "1E+309", ".5", "123456789.0", "-3.0E38"]
CHARS = ["'A'", "'AB'", "'ABCD'", "'ABCDE'", "''", "'\u00e4'", "'\u4e2d'", "'A"]
STRINGS = ['"Pump 1"', '""', '"A""B"', '"' + "X" * 254 + '"', '"' + "X" * 255 + '"',
           '"\u00e4\u00f6"', '"\u4e2d"', '"unterminated']
POINTERS = ["&VB0", "&VB100", "&VB10239", "&IB0", "&QW0", "&SMB0", "&T37", "&C0", "&AIW0",
            "&MB0", "&LB0", "&I0.0", "&AC1", "&", "&&VB0"]
INDIRECT = ["*VD0", "*VD100", "*LD0", "*AC1", "*AC3", "*AC0", "*VW0", "*VD10237", "**VD0",
            "*#x", "*"]
ODD = ["", ",", "V", "VB", "%", "..", "V" * 300, "VB1e5", "\u00c4", "#", "##x", "(", "x y",
       "Name:M2.0", "SBR0", "OB1", "INT0", "L", "+", "-", "16#", "2#2", "1.2.3", "1E", "e5"]
LABELS = ["0", "1", "255", "256", "-1"]
GENERAL = (BITS + BYTES + WORDS + DWORDS + INTS + REALS + CHARS + STRINGS + POINTERS
           + INDIRECT + ODD)

#: operands of the instructions that take theirs as written
VARIADIC = {
    "ATCH": ["INT0", "10"], "DTCH": ["10"], "CEVNT": ["10"], "PLS": ["0"],
    "HDEF": ["0", "1"], "HSC": ["0"], "PID": ["VB100", "0"], "XMT": ["VB100", "0"],
    "RCV": ["VB100", "0"], "NETR": ["VB100", "0"], "NETW": ["VB100", "0"],
    "GET": ["VB100"], "PUT": ["VB100"], "CALL": ["SBR0"],
}
STACK_OPS = ["LD SM0.0", "LDN I0.0", "A I0.1", "O I0.2", "ALD", "OLD", "LPS", "LRD", "LPP",
             "NOT", "EU", "ED", "AENO", "LDS 1", "LDS 8", "LDS 9", "LDS 0", "= Q0.0",
             "FOR VW300, +1, +3", "NEXT", "LBL 1", "JMP 1", "LSCR S0.0", "SCRE", "SCRT S0.1",
             "CRET", "RET", "END", "MEND", "STOP", "RETI", "CSCRE", "ENI", "DISI"]

_INSN = re.compile(r"^(\s*)(\S+)(\s*)(.*?)(\s*//.*)?$")
_BLOCK = re.compile(r"^\s*(ORGANIZATION_BLOCK|SUBROUTINE_BLOCK|INTERRUPT_BLOCK)\s+(\S+)",
                    re.I)
_VAR = re.compile(r"^\s*([A-Za-z_]\w*)\s*:\s*[A-Za-z]+\s*;")


# -- the samples ---------------------------------------------------------------

@dataclass(frozen=True)
class Sample:
    """One program to mutate, with the files it is loaded with."""

    name: str
    text: str
    symbols: Path | None
    data: Path | None
    plant: Path | None


def _beside(path: Path, *names: str) -> Path | None:
    for name in names:
        p = path.with_name(name)
        if p.is_file():
            return p
    return None


def _samples() -> list[Sample]:
    paths = sorted([*(ROOT / "programs").rglob("*.awl"), *(ROOT / "examples").rglob("*.awl")])
    if CORPUS.is_dir():
        paths += sorted(CORPUS.glob("*.awl"))
    out = []
    for p in paths:
        stem = p.stem
        out.append(Sample(
            str(p.relative_to(ROOT) if p.is_relative_to(ROOT) else p.name),
            p.read_text(encoding="utf-8", errors="replace"),
            _beside(p, f"{stem}_symbols.txt", "symbols.txt", f"{stem}.sdf"),
            _beside(p, f"{stem}.db"),
            _beside(p, f"{stem}_plant.toml", "plant.toml")))
    return out


SAMPLES = _samples()


# -- mutation ------------------------------------------------------------------

class Mutant:
    """The lines of one sample and the mutations applied to them."""

    def __init__(self, sample: Sample, rng: random.Random) -> None:
        self.sample = sample
        self.rng = rng
        self.lines = sample.text.splitlines()
        self.done: list[str] = []

    # what the program holds
    def insn_lines(self) -> list[int]:
        return [i for i, line in enumerate(self.lines) if _is_insn(line)]

    def blocks(self) -> list[tuple[int, str]]:
        """(line index, name) of each block header."""
        out = []
        for i, line in enumerate(self.lines):
            m = _BLOCK.match(line)
            if m:
                out.append((i, m.group(2)))
        return out

    def names(self) -> list[str]:
        """Local variables and symbols the sample uses, and unknown ones."""
        local = [f"#{m.group(1)}" for line in self.lines if (m := _VAR.match(line))]
        words = [w for line in self.lines for w in re.findall(r"\b[A-Za-z_]\w{3,}\b", line)
                 if w.upper() not in REGISTRY]
        picked = self.rng.sample(words, min(4, len(words))) if words else []
        return local + picked + ["#nope", "Unknown_Symbol", "#" + "x" * 300]

    def operand(self) -> str:
        pool = self.rng.choice([GENERAL, GENERAL, BITS, BYTES + WORDS + DWORDS,
                                INTS + REALS + CHARS + STRINGS, POINTERS + INDIRECT,
                                self.names(), LABELS])
        return self.rng.choice(pool)

    def spot(self) -> int:
        """A line index inside a block (after some instruction), or 0."""
        insns = self.insn_lines()
        return self.rng.choice(insns) + self.rng.randint(0, 1) if insns else 0

    # the mutations
    def replace_operand(self) -> None:
        self._edit_operands(lambda ops: self._swap_one(ops))

    def replace_all_operands(self) -> None:
        self._edit_operands(lambda ops: [self.operand() for _ in ops] or [self.operand()])

    def add_or_drop_operand(self) -> None:
        def edit(ops: list[str]) -> list[str]:
            if ops and self.rng.random() < 0.5:
                ops.pop(self.rng.randrange(len(ops)))
            else:
                ops.insert(self.rng.randint(0, len(ops)), self.operand())
            return ops
        self._edit_operands(edit)

    def huge_constants(self) -> None:
        def edit(ops: list[str]) -> list[str]:
            return [self.rng.choice(INTS[12:] + REALS[3:9]) if re.fullmatch(r"[+-]?[\d.]+\S*", o)
                    else o for o in ops]
        self._edit_operands(edit)

    def other_mnemonic(self) -> None:
        """Another instruction with the operands of this one."""
        i = self._pick_insn()
        if i is None:
            return
        m = _INSN.match(self.lines[i])
        new = self.rng.choice(MNEMONICS)
        self.lines[i] = f"{m.group(1)}{new} {m.group(4)}"
        self.done.append(f"line {i + 1}: mnemonic -> {new}")

    def signature_insn(self) -> None:
        """Any instruction with operands that fit its signature but one."""
        mn = self.rng.choice(MNEMONICS)
        spec = REGISTRY[mn]
        ops = list(VARIADIC.get(mn, [])) if spec.variadic else [TYPICAL[r] for r in spec.roles]
        if ops and self.rng.random() < 0.85:
            ops[self.rng.randrange(len(ops))] = self.operand()
        self._insert(f"{mn:6} {', '.join(ops)}".rstrip())

    def signature_batch(self) -> None:
        """Several instructions of one family with one odd operand each
        (refused lines do not stop the others from being compiled)."""
        family = REGISTRY[self.rng.choice(MNEMONICS)].family
        same = [m for m in MNEMONICS if REGISTRY[m].family == family]
        for _ in range(self.rng.randint(3, 12)):
            mn = self.rng.choice(same)
            spec = REGISTRY[mn]
            ops = list(VARIADIC.get(mn, [])) if spec.variadic else \
                [TYPICAL[r] for r in spec.roles]
            if ops:
                ops[self.rng.randrange(len(ops))] = self.operand()
            self._insert(f"{mn:6} {', '.join(ops)}".rstrip())

    def stack_op(self) -> None:
        self._insert(self.rng.choice(STACK_OPS))

    def recursion(self) -> None:
        """A block calls itself, or another block (cycles, calls of OB1/INT)."""
        blocks = self.blocks()
        if not blocks:
            return
        i, name = self.rng.choice(blocks)
        callee = name if self.rng.random() < 0.6 else self.rng.choice(blocks)[1]
        callee = callee.split(":")[self.rng.randint(0, 1) if ":" in callee else 0]
        insns = [k for k in self.insn_lines() if k > i] or [i + 1]
        at = insns[0] + 1
        args = ", ".join(self.operand() for _ in range(self.rng.randint(0, 3)))
        self.lines[at:at] = ["LD     SM0.0", f"CALL   {callee}{', ' + args if args else ''}"]
        self.done.append(f"line {at + 1}: CALL {callee}")

    def delete_line(self) -> None:
        if self.lines:
            i = self.rng.randrange(len(self.lines))
            self.done.append(f"line {i + 1}: deleted {self.lines.pop(i)[:40]!r}")

    def duplicate_line(self) -> None:
        if self.lines:
            i = self.rng.randrange(len(self.lines))
            self.lines.insert(i, self.lines[i])
            self.done.append(f"line {i + 1}: doubled")

    def truncate_network(self) -> None:
        """Drop the rest of a network from one of its instructions on."""
        i = self._pick_insn()
        if i is None:
            return
        j = i
        while j < len(self.lines) and _is_insn(self.lines[j]):
            j += 1
        del self.lines[i:j]
        self.done.append(f"lines {i + 1}..{j}: deleted")

    MUTATIONS = ("replace_operand", "replace_operand", "replace_operand",
                 "replace_all_operands", "add_or_drop_operand", "huge_constants",
                 "other_mnemonic", "signature_insn", "signature_insn", "signature_batch",
                 "signature_batch", "stack_op", "stack_op", "recursion", "delete_line", "duplicate_line",
                 "truncate_network")

    def mutate(self) -> str:
        for _ in range(self.rng.choice((1, 1, 1, 2, 3))):
            getattr(self, self.rng.choice(self.MUTATIONS))()
        return "\n".join(self.lines) + "\n"

    # helpers
    def _pick_insn(self) -> int | None:
        insns = self.insn_lines()
        return self.rng.choice(insns) if insns else None

    def _edit_operands(self, edit) -> None:  # noqa: ANN001
        i = self._pick_insn()
        if i is None:
            return
        m = _INSN.match(self.lines[i])
        ops = _split_operands(m.group(4))
        new = edit(list(ops))
        self.lines[i] = f"{m.group(1)}{m.group(2)}{m.group(3) or ' '}{', '.join(new)}"
        self.done.append(f"line {i + 1}: {self.lines[i].strip()[:80]}")

    def _swap_one(self, ops: list[str]) -> list[str]:
        if not ops:
            return [self.operand()]
        ops[self.rng.randrange(len(ops))] = self.operand()
        return ops

    def _insert(self, text: str) -> None:
        at = self.spot()
        self.lines.insert(at, text)
        self.done.append(f"line {at + 1}: inserted {text[:60]!r}")


def _is_insn(line: str) -> bool:
    t = line.strip()
    if not t or t.startswith("//"):
        return False
    word = t.split(None, 1)[0]
    return word.upper() in REGISTRY


def _split_operands(text: str) -> list[str]:
    """Operands separated by commas outside quotes."""
    out, cur, quote = [], "", ""
    for ch in text:
        if quote:
            cur += ch
            if ch == quote:
                quote = ""
        elif ch in "'\"":
            quote = ch
            cur += ch
        elif ch == ",":
            out.append(cur.strip())
            cur = ""
        else:
            cur += ch
    if cur.strip():
        out.append(cur.strip())
    return out


# -- running -------------------------------------------------------------------

def mutant(i: int, seed: str = SEED) -> tuple[Sample, str, list[str]]:
    """Mutant number *i*: its sample, its text, and what was changed."""
    rng = random.Random(f"{seed}:{i}")
    sample = SAMPLES[i % len(SAMPLES)]
    m = Mutant(sample, rng)
    return sample, m.mutate(), m.done


class PlcrtBug(Exception):
    """A PlcError that reports a bug of plcrt's own instead of the program's."""


#: words of the messages that report plcrt's own bugs (last-resort wrappers)
BUG_MARKS = ("internal error", "bug in plcrt")


def _check_not_a_bug(e: plcrt.PlcError) -> None:
    for d in e.diagnostics:
        if any(mark in d.message for mark in BUG_MARKS):
            raise PlcrtBug(str(d)) from e


def exercise(sample: Sample, text: str, backend: str, with_plant: bool) -> str:
    """Load *text* as *sample* is loaded; scan and fork it if it loads.
    Returns what happened ("refused", "fault", "ran"); any exception but a
    PlcError propagates, and a PlcError that reports a plcrt bug raises
    :class:`PlcrtBug`."""
    try:
        plc = plcrt.load(text, symbols=sample.symbols, data=sample.data,
                         plant=sample.plant if with_plant else None,
                         backend=backend, library=True)
    except plcrt.PlcError as e:
        _check_not_a_bug(e)
        return "refused"
    try:
        plc.run(scans=SCANS)
        twin = plc.fork()
        twin.run(scans=1)
    except plcrt.PlcError as e:
        _check_not_a_bug(e)
        return "fault"
    _check_not_a_bug(plcrt.PlcError("", None, plc.diagnostics))
    return "ran"


def run_mutants(indexes: range, seed: str = SEED) -> tuple[list[str], dict[str, int]]:
    """Every escaped exception of the mutants in *indexes* (a report each),
    and how many mutants ended each way."""
    failures: list[str] = []
    outcomes: dict[str, int] = {}
    native = _native_available()
    for i in indexes:
        sample, text, done = mutant(i, seed)
        backends = ["python"] + (["native"] if native and i % NATIVE_EVERY == 0 else [])
        for backend in backends:
            try:
                how = exercise(sample, text, backend, with_plant=i % 2 == 0)
            except Exception as e:  # noqa: BLE001 - what the test looks for
                frames = traceback.extract_tb(e.__traceback__)[-3:]
                where = "; ".join(f"{Path(f.filename).name}:{f.lineno}" for f in frames)
                failures.append(f"mutant {i} ({sample.name}, {backend}): "
                                f"{type(e).__name__}: {str(e)[:200]} at {where}; "
                                f"changes: {done}")
                how = "escaped"
            outcomes[how] = outcomes.get(how, 0) + 1
    return failures, outcomes


def _native_available() -> bool:
    try:
        import llvmlite  # noqa: F401
    except ImportError:
        return False
    return True


@pytest.fixture
def native_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The native backend's machine code goes to a temporary folder."""
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path))


@pytest.mark.parametrize("chunk", range(CHUNKS))
def test_mutants_end_in_plc_errors_or_run(chunk: int, native_cache: None) -> None:
    """Every mutant is refused with a PlcError or loads, scans and forks;
    no other exception escapes load, a scan or fork."""
    failures, outcomes = run_mutants(range(chunk, MUTANTS, CHUNKS))
    assert not failures, "\n".join(failures[:20]) + f"\n({len(failures)} in all; {outcomes})"


def test_the_mutants_exercise_both_outcomes() -> None:
    """The mutations are neither all fatal nor all harmless: among the
    first mutants some load and run, and some are refused."""
    _, outcomes = run_mutants(range(0, 40))
    assert outcomes.get("ran", 0) >= 5 and outcomes.get("refused", 0) >= 5, outcomes


def test_the_samples_are_found() -> None:
    """The mutants start from the sample programs (and the corpus if present)."""
    names = {s.name for s in SAMPLES}
    assert "programs/seal_in.awl" in names and len(SAMPLES) >= 10
    assert any(s.symbols for s in SAMPLES) and any(s.plant for s in SAMPLES)
