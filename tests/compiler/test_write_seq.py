"""Gen.wr_seq: writes joined into one store leave memory exactly as the
same writes one by one (property test over random outputs at random,
often neighbouring and sometimes overlapping, addresses), and neighbours
are joined."""

from __future__ import annotations

from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from plcrt.compiler.emit import Gen
from plcrt.compiler.operands import Addr
from plcrt.compiler.rt import CODECS

KINDS = ("X", "B", "W", "WU", "D", "DU", "R")
WIDTH = {"X": 0, "B": 1, "W": 2, "WU": 2, "D": 4, "DU": 4, "R": 4}


class _Unit:
    """The part of a compilation unit a Gen needs for writes."""


def _value(kind: str, raw: int) -> Any:
    if kind == "X":
        return raw & 1
    if kind == "R":
        return float(raw % 2000) / 8 - 100.0          # exact in single precision
    return raw - (1 << 40)                             # signed and oversized: masked


@st.composite
def writes(draw: Any) -> list[tuple[Addr, str, int]]:
    out = []
    pos = draw(st.integers(0, 8))
    for _ in range(draw(st.integers(1, 8))):
        kind = draw(st.sampled_from(KINDS))
        area = draw(st.sampled_from(("V", "V", "V", "M", "AC")))
        if area == "AC":
            kind = draw(st.sampled_from(("B", "W", "D")))
            op = Addr("AC", draw(st.integers(0, 3)), WIDTH[kind])
        elif kind == "X":
            op = Addr(area, pos, 0, draw(st.integers(0, 7)))
        else:
            op = Addr(area, pos, WIDTH[kind])
            # usually the next address, sometimes a gap (joined up to two
            # bytes) or an overlap
            pos = max(0, pos + WIDTH[kind] + draw(st.sampled_from((0, 0, 0, 1, 2, 3, -1))))
        out.append((op, kind, draw(st.integers(0, 1 << 41))))
    return out


def _run(items: list[tuple[Addr, str, int]], joined: bool) -> tuple[bytes, ...]:
    g = Gen(_Unit())
    spec = [(op, kind, f"r[{i}]") for i, (op, kind, _) in enumerate(items)]
    if joined:
        g.wr_seq(spec)
    else:
        for op, kind, expr in spec:
            if kind == "X":
                g.wbit(op, expr)
            else:
                g.wr(op, kind, expr)
    # the strategy's last address is at most 8 + 7 * 7 = 57, 4 bytes wide
    areas = {"V": bytearray(range(72)), "M": bytearray(b"\xa5" * 72), "AC": bytearray(16)}
    ns: dict[str, Any] = dict(CODECS, **areas, r=[_value(k, v) for _, k, v in items])
    exec("\n".join(line.strip() for line in g.lines), ns)
    return tuple(bytes(b) for b in areas.values())


@settings(max_examples=300, deadline=None)
@given(writes())
def test_joined_writes_leave_memory_as_single_ones(items: list) -> None:
    assert _run(items, joined=True) == _run(items, joined=False)


def test_neighbouring_outputs_are_one_store() -> None:
    """SPD_CTRL's outputs VD100, VB104, VW106, VD108: one struct call that
    writes VB105 again with its own value; two bits of MB0: one byte store."""
    g = Gen(_Unit())
    g.wr_seq([(Addr("V", 100, 4), "D", "r[0]"), (Addr("V", 104, 1), "B", "r[1]"),
              (Addr("V", 106, 2), "WU", "r[2]"), (Addr("V", 108, 4), "D", "r[3]"),
              (Addr("M", 0, 0, 3), "X", "r[4]"), (Addr("M", 0, 0, 4), "X", "r[5]")])
    assert [line.strip() for line in g.lines] == [
        "_wIBBHI(V, 100, (r[0]) & 4294967295, (r[1]) & 255, V[105], (r[2]) & 65535, "
        "(r[3]) & 4294967295)",
        "M[0] = M[0] & 231 | (r[4]) << 3 | (r[5]) << 4"]


def test_the_same_bit_twice_is_written_twice() -> None:
    g = Gen(_Unit())
    g.wr_seq([(Addr("M", 0, 0, 3), "X", "r[0]"), (Addr("M", 0, 0, 3), "X", "r[1]")])
    assert len(g.lines) == 2


def test_values_three_bytes_apart_are_two_stores() -> None:
    g = Gen(_Unit())
    g.wr_seq([(Addr("V", 0, 2), "W", "r[0]"), (Addr("V", 5, 2), "W", "r[1]")])
    assert len(g.lines) == 2
