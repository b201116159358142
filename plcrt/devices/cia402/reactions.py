"""How a CiA 402 drive stops and faults, and where the two drive models differ.

What it is: the quick stop options of 605Ah (0–8, zero decelerations), the
603Fh error codes with HCFA's alarm numbers and reset rules (HCFA §4.6, §4.7)
plus the CiA 402 codes used where HCFA has none, and the :class:`Personality`
of each model (``hcfa-am0520b``, ``kinco-servo``), every field citing its source.

What it is not: no motion; a quick stop is a plan the mode layer carries out.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from .states import Cia402Error, State

__all__ = [
    "QuickStopPlan", "QUICK_STOP_OPTIONS", "quick_stop_plan", "FaultCode", "FAULT_CODES",
    "Personality", "PERSONALITIES", "personality",
]

S = State


# --------------------------------------------------------------------------- quick stop

Ramp = Literal["none", "6084h", "6085h", "current limit", "voltage limit"]


@dataclass(frozen=True, slots=True)
class QuickStopPlan:
    """What a quick stop with 605Ah = *option* does (CiA 402; digest §1.4)."""

    option: int
    ramp: Ramp                 # how the axis stops
    deceleration: int          # P/s², 0 = at once
    then: State                # SWITCH ON DISABLED (0–4) or QUICK STOP ACTIVE (5–8)
    explanation: str


#: 605Ah option -> (ramp, final state); HCFA §8.3 gives only "0–65535, default 2".
QUICK_STOP_OPTIONS: dict[int, tuple[Ramp, State]] = {
    0: ("none", S.SWITCH_ON_DISABLED),
    1: ("6084h", S.SWITCH_ON_DISABLED), 2: ("6085h", S.SWITCH_ON_DISABLED),
    3: ("current limit", S.SWITCH_ON_DISABLED), 4: ("voltage limit", S.SWITCH_ON_DISABLED),
    5: ("6084h", S.QUICK_STOP_ACTIVE), 6: ("6085h", S.QUICK_STOP_ACTIVE),
    7: ("current limit", S.QUICK_STOP_ACTIVE), 8: ("voltage limit", S.QUICK_STOP_ACTIVE),
}


def quick_stop_plan(option: int, dec_6084: int, dec_6085: int,
                    limit_as_6085h: bool = True,
                    to_sod: frozenset[int] = frozenset({0, 1, 2, 3, 4})) -> QuickStopPlan:
    """The stop a quick stop performs for 605Ah = *option* (0–8).

    *limit_as_6085h*: the current/voltage-limit options 3/4/7/8 ramp on 6085h
    (a stepper has no torque-limited stop).  A ramp whose deceleration is 0 is
    undefined in the manual (6084h/6085h default 0, HCFA §8.3): the axis stops
    at once and the plan says so.  *to_sod*: the options after which the drive
    goes on to SWITCH ON DISABLED by itself (transition 12); the others stay in
    QUICK STOP ACTIVE."""
    if option not in QUICK_STOP_OPTIONS:
        raise Cia402Error(
            f"605Ah quick-stop option code = {option} is not one of 0–8 "
            "(CiA 402; HCFA §8.3 gives no codes): SDO abort 0x06090030")
    ramp, _ = QUICK_STOP_OPTIONS[option]
    then = S.SWITCH_ON_DISABLED if option in to_sod else S.QUICK_STOP_ACTIVE
    if ramp in ("current limit", "voltage limit") and limit_as_6085h:
        ramp = "6085h"
    dec = {"6084h": dec_6084, "6085h": dec_6085}.get(ramp, 0)
    stay = "then stays in QUICK STOP ACTIVE" if then is S.QUICK_STOP_ACTIVE \
        else "then goes to SWITCH ON DISABLED (transition 12)"
    if ramp == "none":
        why = f"605Ah = {option}: the drive is disabled at once, {stay}"
    elif ramp in ("6084h", "6085h") and dec == 0:
        why = (f"605Ah = {option} ramps on {ramp}, but {ramp} = 0 (its default, HCFA "
               f"§8.3): a ramp at 0 is undefined, so the axis stops at once, {stay}")
    elif ramp in ("6084h", "6085h"):
        why = f"605Ah = {option}: ramp to rest on {ramp} = {dec} P/s², {stay}"
    else:
        why = f"605Ah = {option}: stop at the {ramp}, {stay}"
    return QuickStopPlan(option, ramp, dec, then, why)


# --------------------------------------------------------------------------- faults

@dataclass(frozen=True, slots=True)
class FaultCode:
    """One 603Fh error code (HCFA §4.7 table, or a CiA 402 code)."""

    code: int                    # 603Fh value
    alarm: int | None            # the drive's alarm number (HCFA: = 603Fh)
    name: str
    resettable: bool             # False: power cycle only ("否")
    section: str
    led_blinks: int | None = None  # red LED blinks, HCFA §4.6


def _f(code: int, name: str, reset: bool, sec: str = "HCFA §4.7",
       blinks: int | None = None, alarm: bool = True) -> FaultCode:
    return FaultCode(code, code if alarm else None, name, reset, sec, blinks)


#: 603Fh codes the model can raise, keyed by code.  HCFA's alarm numbers are
#: the 603Fh values themselves (§4.7 "故障编号 (603F)").
FAULT_CODES: dict[int, FaultCode] = {f.code: f for f in (
    _f(4, "parameter storage fault", False),
    _f(17, "EtherCAT communication fault", False),
    _f(8, "motor phase loss", False),
    _f(20640, "op-amp fault (current sampling)", False, blinks=9),
    _f(20704, "over-current", False, blinks=1),
    _f(12828, "under-voltage", False, blinks=3),
    _f(12827, "over-voltage", True, blinks=2),
    _f(10256, "encoder deviation", True, blinks=7),
    _f(83, "parameter change needs a power cycle", True),
    _f(62, "invalid homing method", True),
    _f(63, "homing timeout", True),
    _f(35, "PDO mapping error", True),
    _f(70, "SYNC0 error", True),
    _f(71, "severe synchronisation error", True),
    # Standard CiA 402 codes for faults HCFA numbers nowhere (not from the seeds).
    _f(0x8611, "following error (CiA 402, not in the seeds)", True, "CiA 402", alarm=False),
    _f(0x7305, "incremental sensor 1 fault (CiA 402, not in the seeds)", True,
       "CiA 402", alarm=False),
    _f(0x5441, "E-stop input (CiA 402, not in the seeds)", True, "CiA 402", alarm=False),
    _f(0x8612, "reference limit (CiA 402, not in the seeds)", True, "CiA 402", alarm=False),
    # The Kinco note numbers no fault: its injectable ones take CiA 402 codes,
    # power-cycle-only as HCFA's over-current and op-amp faults (§4.7).
    _f(0x2310, "continuous over-current (CiA 402, not in the seeds)", False, "CiA 402",
       alarm=False),
    _f(0x5400, "power stage (CiA 402, not in the seeds)", False, "CiA 402", alarm=False),
    _f(0x3210, "DC link over-voltage (CiA 402, not in the seeds)", True, "CiA 402",
       alarm=False),
    _f(0x3220, "DC link under-voltage (CiA 402, not in the seeds)", False, "CiA 402",
       alarm=False),
)}


# --------------------------------------------------------------------------- personality

@dataclass(frozen=True, slots=True)
class Personality:
    """Where a drive model departs from the HCFA tables or the standard.

    Each field is paired with ``sources`` naming where its value comes from."""

    model: str
    bit15: Literal["can-trigger", "reference-found"]
    transition_16_options: frozenset[int]   # 605Ah values that allow QSA -> OE
    auto_qsa_to_sod_options: frozenset[int]  # 605Ah values ending in transition 12
    enable_from_ready: Literal["two-step", "through"]
    limit_stops_as_6085h: bool
    idle_statuswords: bool                  # use the HCFA §7.3 per-mode idle table
    default_quick_stop_option: int
    pp_following_error_bit13: bool          # PP bit 13 = following error (6065h/6066h)
    sources: dict[str, str] = field(default_factory=dict)


PERSONALITIES: dict[str, Personality] = {
    "hcfa-am0520b": Personality(
        model="hcfa-am0520b", bit15="can-trigger",
        transition_16_options=frozenset({5, 6, 7, 8}),
        auto_qsa_to_sod_options=frozenset({0, 1, 2, 3, 4}),
        enable_from_ready="two-step", limit_stops_as_6085h=True,
        idle_statuswords=True, default_quick_stop_option=2,
        pp_following_error_bit13=False,
        sources={
            "bit15": "HCFA §7.5.3 / §7.5.4: bit 15 = a move or homing can be triggered",
            "transition_16_options": "HCFA §7.2 row 16 lists QSA->OE; allowed only for "
                                     "605Ah 5–8 as CiA 402-2 (digest §1.3 rule 3)",
            "auto_qsa_to_sod_options": "HCFA §7.2 row 12 (automatic); CiA 402 codes 0–4",
            "enable_from_ready": "HCFA §7.4.1 footnote **: 0x000F in READY TO SWITCH ON "
                                 "gives Switched on (3); 4 follows at the next evaluation",
            "limit_stops_as_6085h": "a stepper has no torque-limited stop (digest §1.4)",
            "idle_statuswords": "HCFA §7.3 per-mode table",
            "default_quick_stop_option": "HCFA §8.3: 605Ah default 2",
            "pp_following_error_bit13": "HCFA §7.5.3 defines no PP bit 13",
        }),
    "kinco-servo": Personality(
        model="kinco-servo", bit15="reference-found",
        transition_16_options=frozenset({5, 6, 7, 8}),
        auto_qsa_to_sod_options=frozenset({0, 1, 2, 3, 4}),
        enable_from_ready="through", limit_stops_as_6085h=False,
        idle_statuswords=False, default_quick_stop_option=2,
        pp_following_error_bit13=True,
        sources={
            "bit15": "Kinco §2.6: bit 15 Reference_Found, stays set once homed",
            "transition_16_options": "CiA 402-2 (Kinco seed silent)",
            "auto_qsa_to_sod_options": "CiA 402-2 (Kinco seed silent)",
            "enable_from_ready": "CiA 402-2: 3 then 4 in one evaluation (Kinco seed silent)",
            "limit_stops_as_6085h": "a servo stops at its current limit (CiA 402)",
            "idle_statuswords": "Kinco §2.6 gives the bits only, no per-mode values",
            "default_quick_stop_option": "CiA 402 default 2 (Kinco seed silent)",
            "pp_following_error_bit13": "Kinco §2.6: bit 13 following error (CiA 402 PP: "
                                        "|60F4h| beyond 6065h for 6066h)",
        }),
}


def personality(model: str) -> Personality:
    """The personality of drive *model*; an unknown model is a located error."""
    try:
        return PERSONALITIES[model]
    except KeyError:
        raise Cia402Error(f"unknown CiA 402 drive model {model!r}; known: "
                          + ", ".join(sorted(PERSONALITIES))) from None
