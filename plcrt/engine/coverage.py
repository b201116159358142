"""Network and rung-output coverage, filled in by instrumented code.

When a program is loaded with ``instrument=True`` the code generator adds
two kinds of probes (and nothing else changes in what the program does):

* at the start of every network piece ``_NC[k] = 1``: network ``k`` ran in
  this scan (it is skipped when a JMP jumps over it, its SCR segment is
  inactive, or its subroutine is not called);
* before every coil and box (the outputs of a rung, see
  :mod:`plcrt.isa.shape`) ``_OC[j] |= 2 if <power> else 1``: bit 0 = the
  output was reached without power flow, bit 1 = with power flow.  An output
  that saw both has had each of its rung's outcomes exercised: the ladder
  equivalent of branch (decision) coverage;
* at every contact ``_CC[2 * j + <closed>] = 1``: byte ``2j`` = evaluated
  open, byte ``2j + 1`` = closed (reported as bit 0 and bit 1, as the
  outputs are).  A parallel branch whose contact was never closed never
  conducted: the ladder form of condition coverage.  (perf: a store
  without a read, the cheapest probe on both backends; contacts are most
  of a boolean program's probes.)

A contact on a bit that is constant in RUN (SM0.0) and an output whose
power is constant because of such contacts get no probe: they are not
coverage goals (:mod:`plcrt.compiler.constpower` decides which).

The first piece of every network also checks ``_BP[k]`` and calls the
break handler, which the debugger uses for breakpoints on networks.

This module holds the tables and the report; it does not run anything.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from ..errors import SourceLoc


@dataclass(frozen=True)
class NetworkRef:
    """One network of the program, as Micro/WIN numbers it."""

    index: int
    block: str          #: "OB1", "SBR0", ...
    number: int
    title: str
    loc: SourceLoc

    @property
    def name(self) -> str:
        return f"{self.block}/{self.number}"


@dataclass(frozen=True)
class OutputRef:
    """One coil or box of a rung (an outcome of the network's logic), or
    one contact."""

    index: int
    network: int        #: index into the network list
    mnemonic: str
    operand: str        #: first operand as written ("" when none)
    loc: SourceLoc


class CoverageMap:
    """Probe tables of one instrumented program."""

    def __init__(self) -> None:
        self.networks: list[NetworkRef] = []
        self.outputs: list[OutputRef] = []
        self.hits = bytearray()          #: per network: 1 = ran (since reset)
        self.power = bytearray()         #: per output: bit0 unpowered, bit1 powered
        self.contacts: list[OutputRef] = []
        #: per contact two bytes: [2j] seen open, [2j + 1] seen closed
        self.closed = bytearray()
        self.breakpoints = bytearray()   #: per network: 1 = break before it
        self.on_break: Callable[[NetworkRef], None] | None = None
        #: perf: one bound method for every probe to share
        self.call_hit = self.hit
        self._by_key: dict[tuple[str, int], int] = {}

    # -- filled by the code generator -------------------------------------
    def add_network(self, block: str, number: int, title: str, loc: SourceLoc) -> int:
        key = (block, number)
        if key in self._by_key:
            return self._by_key[key]
        k = len(self.networks)
        self.networks.append(NetworkRef(k, block, number, title, loc))
        self._by_key[key] = k
        self.hits.append(0)
        self.breakpoints.append(0)
        return k

    def add_output(self, network: int, mnemonic: str, operand: str, loc: SourceLoc) -> int:
        j = len(self.outputs)
        self.outputs.append(OutputRef(j, network, mnemonic, operand, loc))
        self.power.append(0)
        return j

    def add_contact(self, network: int, mnemonic: str, operand: str, loc: SourceLoc) -> int:
        j = len(self.contacts)
        self.contacts.append(OutputRef(j, network, mnemonic, operand, loc))
        self.closed += b"\0\0"
        return j

    # -- run time ---------------------------------------------------------
    def hit(self, k: int) -> None:
        """Called by generated code before network ``k`` when it has a breakpoint."""
        if self.on_break is not None:
            self.on_break(self.networks[k])

    def find(self, block: str, number: int) -> NetworkRef | None:
        k = self._by_key.get((block.upper(), number))
        return None if k is None else self.networks[k]

    def reset(self) -> None:
        """Forget what ran (breakpoints stay)."""
        self.hits[:] = bytes(len(self.hits))
        self.power[:] = bytes(len(self.power))
        self.closed[:] = bytes(len(self.closed))

    # -- results ----------------------------------------------------------
    def data(self) -> dict[str, Any]:
        """Plain data (JSON-able): what ran, keyed by stable names."""
        return {
            "networks": {n.name: int(self.hits[n.index]) for n in self.networks},
            "outputs": {self.output_key(o): int(self.power[o.index]) for o in self.outputs},
            "contacts": {self.output_key(c): self.contact_bits(c.index) for c in self.contacts},
        }

    def contact_bits(self, j: int) -> int:
        """Contact ``j``: bit 0 seen open, bit 1 seen closed."""
        return (1 if self.closed[2 * j] else 0) | (2 if self.closed[2 * j + 1] else 0)

    def output_key(self, o: OutputRef) -> str:
        net = self.networks[o.network]
        return f"{net.name}:{o.loc.line}:{o.loc.column}:{o.mnemonic}"


#: the kinds of probes in :meth:`CoverageMap.data`
PARTS = ("networks", "outputs", "contacts")


def merge_data(a: dict[str, Any], b: dict[str, Any]) -> dict[str, Any]:
    """Union of two :meth:`CoverageMap.data` results of the same program."""
    out: dict[str, Any] = {}
    for part in PARTS:
        out[part] = dict(a.get(part, {}))
        for key, v in b.get(part, {}).items():
            out[part][key] = out[part].get(key, 0) | v
    return out


__all__ = ["PARTS", "CoverageMap", "NetworkRef", "OutputRef", "merge_data"]
