"""CiA 402 homing methods as data: one row per method and drive model.

A row says which signal defines home (negative limit, positive limit, a
level home switch read on one edge, the home-switch zone, the index pulse
alone, the present position, a mechanical end), which edge, the first
search direction, the final approach direction, whether the home point is
the first index pulse beyond the edge, and which limit reverses the search.
The geometry is that of shared/reference/homing-and-motion.md §1.2 and the
digest shared/reference/cia402.md §4.2; the path each model drives to get
there is in :mod:`.homing`.  Each row cites the section of its model's
document.  This module holds no behaviour beyond reading the plant.

Plant conventions (docs/cia402.md, "Homing"):

* the negative limit NLS is active at positions ``<= neg_limit``, the
  positive limit PLS at ``>= pos_limit``;
* the home switch is the zone ``[lo, hi]``.  Methods 3, 4, 19, 20 read it as
  a *positive* level switch (active right of ``lo``: only the ``lo`` edge
  matters), methods 5, 6, 21, 22 as a *negative* one (active left of ``hi``),
  methods 7-14 and 23-30 as a zone with both edges;
* index pulses lie at ``index_phase + k * index_period``;
* mechanical ends (hard stops, Kinco -17/-18) at ``neg_stop`` /
  ``pos_stop`` (the names of :class:`~.plant.DrivePlant`): the axis cannot
  pass them.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import PlcConfigError
from ..homing_geometry import edge_crossing, zone_entry

__all__ = ["HomingPlant", "Method", "METHODS", "MODELS", "method_table"]

NLS, PLS = "nls", "pls"
HS_POS, HS_NEG, HS_ZONE = "hs_pos", "hs_neg", "hs_zone"
INDEX, HERE, HARD_STOP = "index", "here", "hard_stop"

SIGNAL_NAMES = {
    NLS: "negative limit switch (NLS)", PLS: "positive limit switch (PLS)",
    HS_POS: "home switch (positive level)", HS_NEG: "home switch (negative level)",
    HS_ZONE: "home switch (zone)", INDEX: "index pulse", HERE: "present position",
    HARD_STOP: "mechanical end", "neg_stop": "negative mechanical end",
    "pos_stop": "positive mechanical end",
}


@dataclass(frozen=True)
class HomingPlant:
    """The axis as the homing sees it (positions in counts)."""

    neg_limit: int | None = None
    pos_limit: int | None = None
    home_switch: tuple[int, int] | None = None
    index_period: int | None = None
    index_phase: int = 0
    neg_stop: int | None = None
    pos_stop: int | None = None

    def __post_init__(self) -> None:
        if self.home_switch is not None and self.home_switch[0] > self.home_switch[1]:
            raise PlcConfigError(f"homing plant: home_switch {self.home_switch} has lo > hi")
        if self.index_period is not None and self.index_period <= 0:
            raise PlcConfigError(f"homing plant: index_period {self.index_period} must be > 0")
        if (self.neg_limit is not None and self.pos_limit is not None
                and self.neg_limit >= self.pos_limit):
            raise PlcConfigError(f"homing plant: neg_limit {self.neg_limit} must lie left of "
                                 f"pos_limit {self.pos_limit}")
        if self.neg_stop is not None and self.pos_stop is not None \
                and self.neg_stop >= self.pos_stop:
            raise PlcConfigError(f"homing plant: neg_stop {self.neg_stop} must lie left of "
                                 f"pos_stop {self.pos_stop}")

    def limit_active(self, which: str, x: int) -> bool:
        if which == NLS:
            return self.neg_limit is not None and x <= self.neg_limit
        return self.pos_limit is not None and x >= self.pos_limit

    def limit_position(self, which: str) -> int | None:
        """First active position of a limit (moving toward it)."""
        return self.neg_limit if which == NLS else self.pos_limit


@dataclass(frozen=True)
class Method:
    """One homing method of one drive model (see the module docstring)."""

    number: int
    signal: str            #: NLS, PLS, HS_POS, HS_NEG, HS_ZONE, INDEX, HERE, HARD_STOP
    edge: str | None       #: "lo" / "hi" edge of the home switch (switch methods)
    search: int            #: first direction when starting off the signal (0: no motion)
    final: int             #: direction of the final approach (0: no motion)
    index: bool            #: home is the first index pulse at or beyond the edge
    reverse_at: str | None  #: limit that reverses the search (7-14, 23-30)
    source: str            #: section of the model's document

    def needs(self) -> list[str]:
        """The plant signals this method cannot do without."""
        need = []
        if self.signal in (NLS, PLS):
            need.append(self.signal)
        if self.signal in (HS_POS, HS_NEG, HS_ZONE):
            need.append("home_switch")
        if self.signal == HARD_STOP:
            need.append("neg_stop" if self.search < 0 else "pos_stop")
        if self.index:
            need.append("index_period")
        return need

    def active(self, plant: HomingPlant, x: int) -> bool:
        """Is the method's switch active at ``x``?"""
        if self.signal in (NLS, PLS):
            return plant.limit_active(self.signal, x)
        if plant.home_switch is None:
            return False
        lo, hi = plant.home_switch
        if self.signal == HS_POS:
            return x >= lo
        if self.signal == HS_NEG:
            return x <= hi
        if self.signal == HS_ZONE:
            return lo <= x <= hi
        return False

    def entry(self, plant: HomingPlant, x: int, d: int) -> int | None:
        """First active position ahead of ``x`` (inactive) moving ``d``."""
        if self.signal in (NLS, PLS):
            lim = plant.limit_position(self.signal)
            if lim is None or (self.signal == NLS) != (d < 0):
                return None
            return lim
        if plant.home_switch is None:
            return None
        lo, hi = plant.home_switch
        if self.signal == HS_POS:
            return lo if d > 0 and x < lo else None
        if self.signal == HS_NEG:
            return hi if d < 0 and x > hi else None
        return zone_entry(x, d, lo, hi)

    def crossing(self, plant: HomingPlant, start: int) -> int:
        """The reference crossing: first position past the defining edge,
        moving in the final direction (for index-only methods: the first
        position beyond the start, so that a start on an index moves on)."""
        f = self.final
        if self.signal == NLS:
            assert plant.neg_limit is not None
            return plant.neg_limit + 1
        if self.signal == PLS:
            assert plant.pos_limit is not None
            return plant.pos_limit - 1
        if self.signal in (HS_POS, HS_NEG, HS_ZONE):
            assert plant.home_switch is not None and self.edge is not None
            return edge_crossing(self.edge, f, *plant.home_switch)
        return start + f


def _rows(model: str) -> dict[int, Method]:
    hcfa = model == "hcfa-am0520b"
    sec = "HCFA §10.1" if hcfa else "Kinco §2.2/§2.5"
    rows: dict[int, Method] = {}

    def add(n: int, signal: str, edge: str | None, search: int, final: int,
            index: bool, reverse_at: str | None = None, source: str = sec) -> None:
        rows[n] = Method(n, signal, edge, search, final, index, reverse_at, source)

    for base, index in ((0, True), (16, False)):
        add(base + 1, NLS, None, -1, +1, index)
        add(base + 2, PLS, None, +1, -1, index)
        add(base + 3, HS_POS, "lo", +1, -1, index)
        add(base + 4, HS_POS, "lo", +1, +1, index)
        add(base + 5, HS_NEG, "hi", -1, +1, index)
        add(base + 6, HS_NEG, "hi", -1, -1, index)
        for n, edge, final in ((7, "lo", -1), (8, "lo", +1), (9, "hi", -1), (10, "hi", +1)):
            add(base + n, HS_ZONE, edge, +1, final, index, PLS)
        for n, edge, final in ((11, "hi", +1), (12, "hi", -1), (13, "lo", +1), (14, "lo", -1)):
            add(base + n, HS_ZONE, edge, -1, final, index, NLS)
    idx_src = "HCFA §7.5.4 (error table)" if hcfa else "Kinco §2.5"
    add(33, INDEX, None, -1, -1, True, source=idx_src)
    add(34, INDEX, None, +1, +1, True, source=idx_src)
    if hcfa:
        # §7.5.4 "supports all homing methods except ___" (the exception is lost) with
        # 6098h 0-100: the CiA 402 "current position" methods are kept (docs/cia402.md)
        add(35, HERE, None, 0, 0, False, source="HCFA §7.5.4 (CiA 402-2 method 35)")
        add(37, HERE, None, 0, 0, False, source="HCFA §7.5.4 (CiA 402-2 method 37)")
    else:
        add(35, HERE, None, 0, 0, False, source="Kinco §2.5")
        add(-17, HARD_STOP, None, -1, -1, False, source="Kinco §2.5")
        add(-18, HARD_STOP, None, +1, +1, False, source="Kinco §2.5")
    return rows


MODELS = ("hcfa-am0520b", "kinco-servo")
METHODS: dict[str, dict[int, Method]] = {m: _rows(m) for m in MODELS}


def method_table(model: str) -> dict[int, Method]:
    """The supported methods of ``model`` by number."""
    try:
        return METHODS[model]
    except KeyError:
        raise PlcConfigError(f"unknown drive model {model!r} for homing "
                             f"(known: {', '.join(MODELS)})") from None
