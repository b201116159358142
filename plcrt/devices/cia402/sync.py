"""The sync cycles a drive model takes (HCFA §7.4.3, §6.2, §6.8).

What it is: the limits of the bus cycle a drive synchronises to, as data, and
the two checks that use them: the EtherCAT one at PRE-OP -> SAFE-OP (the
cycle of 1C32h:02 in SM-synchronous or DC SYNC0 mode, 1C32h:01 = 1 / 2,
outside the limits: AL status 0x0035 "DC invalid sync cycle time" /
0x0036 "DC invalid SYNC0 cycle time") and the CANopen one (1006h,
communication cycle period, outside the limits: SDO abort 0x06090030).

HCFA §7.4.3 gives 200 µs to 10 ms ("支持的同步周期默认为 200us~10ms"); §6.2
lists 250, 500, 750 µs and 1, 2, 4, 8 … 10 ms as the cycles it was tested
at.  The model takes the §7.4.3 range (a cycle of 300 µs is inside it).
The Kinco note gives no limit: any cycle is taken.

What it is not: no timing; the ports run the cycles.
"""

from __future__ import annotations

from typing import Any, Optional

__all__ = ["SYNC_CYCLE_US", "cycle_limits", "dc_cycle_problem", "drive_cycle_problem",
           "can_cycle_problem"]

#: model -> (shortest, longest) sync cycle in µs.
SYNC_CYCLE_US: dict[str, tuple[int, int]] = {"hcfa-am0520b": (200, 10_000)}
_SOURCE = {"hcfa-am0520b": "HCFA §7.4.3"}


def cycle_limits(model: str) -> Optional[tuple[int, int]]:
    """The (shortest, longest) sync cycle of *model* in µs, None if unbounded."""
    return SYNC_CYCLE_US.get(model)


def dc_cycle_problem(model: str, sync_mode: int, cycle_ns: int) -> Optional[tuple[int, str]]:
    """(AL status code, why) when the EtherCAT cycle 1C32h:02 = *cycle_ns* is
    one *model* cannot synchronise to in sync mode 1C32h:01 = *sync_mode*
    (0 free run: any cycle), else None."""
    limits = cycle_limits(model)
    if limits is None or sync_mode == 0:
        return None
    lo, hi = limits
    if lo * 1000 <= cycle_ns <= hi * 1000:
        return None
    code = 0x0036 if sync_mode == 2 else 0x0035
    kind = "SYNC0" if sync_mode == 2 else "SM2-synchronous"
    return code, (f"1C32h:02 = {cycle_ns} ns: the {kind} cycle must lie between {lo} µs and "
                  f"{hi} µs ({_SOURCE[model]})")


def drive_cycle_problem(drive: Any) -> Optional[tuple[int, str]]:
    """:func:`dc_cycle_problem` of a drive's own 1C32h (the ESM's sync check;
    a model without 1C32h has none)."""
    if drive.od.find(0x1C32, 2) is None:
        return None
    return dc_cycle_problem(drive.model, int(drive.param(0x1C32, 1)),
                            int(drive.param(0x1C32, 2)))


def can_cycle_problem(model: str, cycle_us: int) -> Optional[str]:
    """Why 1006h = *cycle_us* µs is refused (SDO abort 0x06090030), else None;
    0 (no SYNC period set) is always taken."""
    limits = cycle_limits(model)
    if limits is None or cycle_us == 0 or limits[0] <= cycle_us <= limits[1]:
        return None
    return (f"1006h := {cycle_us} µs: the drive takes a sync cycle of {limits[0]} µs to "
            f"{limits[1]} µs ({_SOURCE[model]}; on EtherCAT AL 0x0035/0x0036)")
