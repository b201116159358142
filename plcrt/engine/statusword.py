"""The CiA 402 statusword 6041h in words: what a display shows of a drive.

What it is: :func:`describe_statusword`, the names of the bits set in a
statusword for the mode shown in 6061h and the model (HCFA §7.4.2 for the
common bits, §7.5.3 PP, §7.5.4 HM, §7.6 PV/CSP; Kinco §2.6 for its bit 15),
as tables, for :attr:`plcrt.engine.device.DriveState.flags`.  It sits in
the engine with the states the API reports; the drives
(:mod:`plcrt.devices.cia402`) build on it, never the other way round.  The
power state itself comes from
:func:`plcrt.devices.cia402.states.state_of_statusword`.

What it is not: no state logic; the drive sets the bits, this only reads them.
"""

from __future__ import annotations

__all__ = ["COMMON_BITS", "MODE_BITS", "describe_statusword"]

#: bits with one meaning in every mode (HCFA §7.4.2); 0–3, 5, 6 make the
#: power state and are shown as the state, 4 and 9 are set in every state
COMMON_BITS: dict[int, str] = {
    7: "warning",
    8: "halted",
    11: "internal limit active",
}

#: the mode-specific bits 10, 12, 13 (and HCFA's 14 / 15) by 6061h
MODE_BITS: dict[int, dict[int, str]] = {
    1: {10: "target reached", 12: "set-point acknowledge", 13: "following error",
        14: "parameter zero"},                                              # HCFA §7.5.3
    3: {10: "target reached", 12: "speed zero", 13: "max slippage"},        # HCFA §7.6
    6: {10: "target reached", 12: "homing attained", 13: "homing error",
        14: "homing parameter zero"},                                       # HCFA §7.5.4
    8: {10: "target reached", 12: "target position followed",
        13: "following error"},                                             # HCFA §7.6
}

#: statusword bit 15 differs between the vendors (docs/cia402.md, decisions log)
BIT15: dict[str, str] = {"kinco-servo": "reference found"}


def describe_statusword(sw: int, mode: int = 0, model: str = "") -> list[str]:
    """Names of the set bits of *sw* beyond the power state, e.g.
    ``["target reached", "set-point acknowledge"]``; bit 15 only where the
    model gives it a meaning the display needs (Kinco's reference found)."""
    names = dict(COMMON_BITS)
    names.update(MODE_BITS.get(mode, {}))
    if model in BIT15:
        names[15] = BIT15[model]
    return [name for bit, name in sorted(names.items()) if sw >> bit & 1]
