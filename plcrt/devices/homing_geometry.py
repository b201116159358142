"""Homing geometry shared by the EM253 homing modes and the CiA 402 methods.

Only pure functions of positions live here: which position the axis is at
when it crosses a switch edge in a given direction, and which index (Z)
pulse is the first at or beyond a position.  The EM253 sequence
(:mod:`plcrt.devices.em253.homing`) and the CiA 402 sequence
(:mod:`plcrt.devices.cia402.homing`) each keep their own method tables and
phase logic: the EM253 runs on its axis with a fixed 100 ms ramp, no
speeds of its own for the approach and stops at once (appendix 1), while a
CiA 402 drive ramps with 609Ah, has two homing speeds and vendor path rules
(HCFA §10.1, Kinco §2.5).  Sharing more than the geometry would bend one of
them toward the other, so only this is shared.

Conventions (shared/reference/homing-and-motion.md §1.2): positions are
integer counts, negative is left; a home-switch zone is the closed range
``[lo, hi]`` of positions at which the switch is active.  An edge is named
by the end of the zone it bounds ("lo" / "hi"), never by "rising" or
"falling" (sources name edges inconsistently).  A crossing is the *first
position on the far side* of the edge, seen while moving in ``direction``.
"""

from __future__ import annotations

__all__ = ["edge_crossing", "index_at_or_beyond", "zone_entry"]


def edge_crossing(edge: str, direction: int, lo: int, hi: int) -> int:
    """First position on the far side of zone edge ``edge`` ("lo"/"hi")
    when the axis crosses it moving in ``direction`` (+1 / -1).

    Moving + across "lo" enters the zone at ``lo``; moving - across it
    leaves at ``lo - 1``; moving - across "hi" enters at ``hi``; moving +
    across it leaves at ``hi + 1``.
    """
    if edge == "lo":
        return lo if direction > 0 else lo - 1
    if edge == "hi":
        return hi + 1 if direction > 0 else hi
    raise ValueError(f"edge must be 'lo' or 'hi', not {edge!r}")


def zone_entry(position: int, direction: int, lo: int, hi: int) -> int | None:
    """First position inside ``[lo, hi]`` reached from ``position`` (outside
    the zone) moving in ``direction``, or None when the zone is not ahead."""
    if direction > 0 and position < lo:
        return lo
    if direction < 0 and position > hi:
        return hi
    return None


def index_at_or_beyond(position: int, direction: int, period: int, phase: int) -> int:
    """First index pulse position at or beyond ``position`` in
    ``direction``; index pulses lie at ``phase + k * period``."""
    if direction > 0:
        k = -((phase - position) // period)   # ceil((position - phase) / period)
    else:
        k = (position - phase) // period      # floor
    return phase + k * period
