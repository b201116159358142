"""The call graph of a program checked against the S7-200's nesting limit.

:func:`check_calls` finds recursion and call chains deeper than eight
levels, warns about each, and switches on the run-time nesting check for
such a program (:attr:`Unit.nest_check`, :attr:`Unit.recursive_sites`).
Every walk is iterative: a hostile program may chain thousands of blocks.
It generates no code; ``CALL``'s emitter (:mod:`plcrt.isa.control`) reads
what it decided.
"""

from __future__ import annotations

from ..gen.limits import MAX_NESTING
from .unit import Unit


def check_calls(unit: Unit) -> None:
    """Check the call graph against the S7-200's nesting limit.

    System Manual, CALL: subroutines nest at most eight levels deep from
    the main program; recursion is allowed ("use caution").  So recursion
    and call chains deeper than eight are warnings here (naming the cycle
    or the chain), and they switch on the run-time nesting check
    (:attr:`Unit.nest_check`): a CALL that would be the ninth level is not
    executed, sets SM4.3 and gives ENO 0 (error 0008).  Call sites inside a
    cycle (:attr:`Unit.recursive_sites`) get one L buffer per nesting level.
    A program without either pays nothing at run time.
    """
    order = list(unit.pous)
    comp = _components(unit, order)
    for ident in order:
        info = unit.pous[ident]
        for callee, loc in info.calls.items():
            if comp[callee] == comp[ident]:
                unit.recursive_sites.add((ident, callee))
    reported: set[int] = set()
    for ident in order:
        info = unit.pous[ident]
        cycle = [] if comp[ident] in reported else _cycle(unit, ident, comp)
        if cycle:
            reported.add(comp[ident])
            shown = cycle + [cycle[0]]
            if len(shown) > 7:   # a hostile program's cycle of thousands of blocks
                shown = shown[:3] + [f"... ({len(cycle)} blocks) ..."] + shown[-2:]
            names = " -> ".join(shown)
            loc = info.calls[cycle[1] if len(cycle) > 1 else ident]
            unit.diag.warning(
                f"recursion: {names}; the S7-200 allows it but nests subroutines at most "
                f"{MAX_NESTING} levels deep: a deeper CALL is not executed (SM4.3 is set)",
                loc, "recursion")
            unit.nest_check = True
    if unit.nest_check:
        return
    height = _heights(unit)
    for ident, info in unit.pous.items():
        if info.pou.kind != "SBR" and height[ident] > MAX_NESTING:
            deepest = max(info.calls, key=height.__getitem__)
            unit.diag.warning(f"subroutine calls from {ident} nest {height[ident]} levels "
                              f"deep; the S7-200 allows {MAX_NESTING}: a deeper CALL is not "
                              f"executed (SM4.3 is set)", info.calls[deepest], "nesting")
            unit.nest_check = True


def _heights(unit: Unit) -> dict[str, int]:
    """How many subroutine levels each block's deepest call chain has (the
    call graph has no cycle here).  Iterative: a hostile program may chain
    thousands of blocks, deeper than Python's recursion limit."""
    memo: dict[str, int] = {}
    for root in unit.pous:
        stack = [(root, False)]
        while stack:
            node, children_done = stack.pop()
            if node in memo:
                continue
            calls = unit.pous[node].calls
            if children_done:
                memo[node] = max((1 + memo[c] for c in calls), default=0)
            else:
                stack.append((node, True))
                stack.extend((c, False) for c in calls if c not in memo)
    return memo


def _components(unit: Unit, order: list[str]) -> dict[str, int]:
    """Strongly connected components of the call graph (Tarjan), as a
    component number per block; blocks in one cycle share a number."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    comp: dict[str, int] = {}

    def visit(v: str) -> None:
        # iterative: a hostile program may chain thousands of blocks
        work = [(v, iter(unit.pous[v].calls))]
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        while work:
            node, edges = work[-1]
            for w in edges:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(unit.pous[w].calls)))
                    break
                if w in on:
                    low[node] = min(low[node], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    n = len(set(comp.values()))
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp[w] = n
                        if w == node:
                            break

    for v in order:
        if v not in index:
            visit(v)
    return comp


def _cycle(unit: Unit, start: str, comp: dict[str, int]) -> list[str]:
    """A call cycle through ``start`` (``[start, ..., last]``, where last
    calls start), or [] when ``start`` is not recursive."""
    if start in unit.pous[start].calls:
        return [start]
    # breadth-first inside the component, for the shortest cycle
    prev: dict[str, str] = {}
    queue = [start]
    for node in queue:
        for c in unit.pous[node].calls:
            if comp.get(c) != comp[start]:
                continue
            if c == start:
                path = [node]
                while path[-1] != start:
                    path.append(prev[path[-1]])
                return list(reversed(path))
            if c not in prev:
                prev[c] = node
                queue.append(c)
    return []


__all__ = ["check_calls"]
