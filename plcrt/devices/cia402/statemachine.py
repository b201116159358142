"""The CiA 402 power state machine of a bus drive, as tables (HCFA §7.2–§7.4).

What it is: the eight states, the transitions 0–16 as a data table
``(state, command) -> (next state, transition, manual §)``, the controlword
6040h decoded as levels (bits 0–3 and 7; fault reset on the rising edge of
bit 7 only), the statusword 6041h per state with HCFA's vendor bits and
per-mode idle values, the quick stop options of 605Ah, the fault reaction with
the 603Fh codes / alarm numbers of HCFA §4.7, and :class:`Drive402`, which
applies controlwords and faults and keeps a numbered event log in which every
command that changes nothing is explained.

What it is not: it has no clock and no motion.  Time is a number the caller
passes in and only recorded; a quick stop or a fault reaction is returned as an
:class:`Action` for the mode layer to carry out, which then reports the axis at
rest with :meth:`Drive402.motion_stopped`.  Modes set the mode-specific
statusword bits (8, 10–15) through :meth:`Drive402.set_mode_bits`.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Literal

from ...errors import PlcConfigError

__all__ = [
    "State", "Command", "Transition", "TRANSITIONS", "AUTOMATIC_TRANSITIONS",
    "STATE_MASKS", "STATUSWORD", "IDLE_STATUSWORD", "QUICK_STOP_OPTIONS",
    "QuickStopPlan", "quick_stop_plan", "FaultCode", "FAULT_CODES",
    "Personality", "PERSONALITIES", "personality", "decode_controlword",
    "state_of_statusword", "Action", "Event", "Result", "Drive402",
    "Cia402Error",
]


class Cia402Error(PlcConfigError):
    """A value given to the drive model is not one the drive can take."""


class State(StrEnum):
    """The power states (HCFA §7.2 figure 5); values are canopen's names."""

    NOT_READY_TO_SWITCH_ON = "NOT READY TO SWITCH ON"
    SWITCH_ON_DISABLED = "SWITCH ON DISABLED"
    READY_TO_SWITCH_ON = "READY TO SWITCH ON"
    SWITCHED_ON = "SWITCHED ON"
    OPERATION_ENABLED = "OPERATION ENABLED"
    QUICK_STOP_ACTIVE = "QUICK STOP ACTIVE"
    FAULT_REACTION_ACTIVE = "FAULT REACTION ACTIVE"
    FAULT = "FAULT"


S = State


class Command(StrEnum):
    """The device control commands of HCFA §7.4.1 (bits 7 and 3–0)."""

    SHUTDOWN = "Shutdown"
    SWITCH_ON = "Switch on"            # also "Disable operation" in OE
    ENABLE_OPERATION = "Enable operation"
    DISABLE_VOLTAGE = "Disable voltage"
    QUICK_STOP = "Quick stop"
    FAULT_RESET = "Fault reset"        # the 0->1 edge of bit 7
    NONE = "no command"                # bit 7 held at 1: nothing matches


#: Typical controlword of each command (HCFA §7.4.1 "6040典型值").
COMMAND_WORD: dict[Command, int] = {
    Command.SHUTDOWN: 0x0006, Command.SWITCH_ON: 0x0007,
    Command.ENABLE_OPERATION: 0x000F, Command.DISABLE_VOLTAGE: 0x0000,
    Command.QUICK_STOP: 0x0002, Command.FAULT_RESET: 0x0080,
}


def decode_controlword(cw: int, previous: int = 0) -> Command:
    """The command of controlword *cw* given the *previous* one (§7.4.1).

    Commands are levels except fault reset, the 0->1 edge of bit 7; while bit 7
    stays 1 no command matches.  Disable voltage is tested first, then quick
    stop, then the rest (masks of the digest §1.3)."""
    if not 0 <= cw <= 0xFFFF:
        raise Cia402Error(f"controlword 6040h = {cw} is not a UINT16 (HCFA §7.4.1)")
    if cw & 0x80:
        return Command.FAULT_RESET if not previous & 0x80 else Command.NONE
    if cw & 0x02 == 0:
        return Command.DISABLE_VOLTAGE
    if cw & 0x06 == 0x02:
        return Command.QUICK_STOP
    if cw & 0x07 == 0x06:
        return Command.SHUTDOWN
    return Command.ENABLE_OPERATION if cw & 0x08 else Command.SWITCH_ON


@dataclass(frozen=True, slots=True)
class Transition:
    """One row of the HCFA §7.2 transition table."""

    number: int
    source: State | None          # None: any state (13) or power-on (0)
    target: State
    trigger: str                  # the command, or "automatic" / "fault"
    statusword: int               # the §7.2 statusword after the transition
    section: str = "HCFA §7.2"


def _t(n: int, src: State | None, dst: State, trig: str, sw: int,
       sec: str = "HCFA §7.2") -> Transition:
    return Transition(n, src, dst, trig, sw, sec)


#: Transitions 0–16, numbered as HCFA §7.2 (and CiA 402).
TRANSITION_ROWS: dict[int, Transition] = {r.number: r for r in (
    _t(0, None, S.NOT_READY_TO_SWITCH_ON, "automatic (power-on)", 0x0000),
    _t(1, S.NOT_READY_TO_SWITCH_ON, S.SWITCH_ON_DISABLED, "automatic", 0x0250),
    _t(2, S.SWITCH_ON_DISABLED, S.READY_TO_SWITCH_ON, "Shutdown", 0x0231),
    _t(3, S.READY_TO_SWITCH_ON, S.SWITCHED_ON, "Switch on", 0x0233, "HCFA §7.2, §7.4.1"),
    _t(4, S.SWITCHED_ON, S.OPERATION_ENABLED, "Enable operation", 0x0237),
    _t(5, S.OPERATION_ENABLED, S.SWITCHED_ON, "Disable operation", 0x0233),
    _t(6, S.SWITCHED_ON, S.READY_TO_SWITCH_ON, "Shutdown", 0x0231),
    _t(7, S.READY_TO_SWITCH_ON, S.SWITCH_ON_DISABLED, "Disable voltage / Quick stop", 0x0250),
    _t(8, S.OPERATION_ENABLED, S.READY_TO_SWITCH_ON, "Shutdown", 0x0231),
    _t(9, S.OPERATION_ENABLED, S.SWITCH_ON_DISABLED, "Disable voltage", 0x0250),
    _t(10, S.SWITCHED_ON, S.SWITCH_ON_DISABLED, "Disable voltage / Quick stop", 0x0250),
    _t(11, S.OPERATION_ENABLED, S.QUICK_STOP_ACTIVE, "Quick stop", 0x0217),
    _t(12, S.QUICK_STOP_ACTIVE, S.SWITCH_ON_DISABLED,
       "automatic once stopped (605Ah 0–4) or Disable voltage", 0x0250),
    _t(13, None, S.FAULT_REACTION_ACTIVE, "fault", 0x021F, "HCFA §7.2, §4.7"),
    _t(14, S.FAULT_REACTION_ACTIVE, S.FAULT, "automatic (reaction done)", 0x0218),
    _t(15, S.FAULT, S.SWITCH_ON_DISABLED, "Fault reset (bit 7 0->1)", 0x0250,
       "HCFA §7.2, §7.4.1"),
    _t(16, S.QUICK_STOP_ACTIVE, S.OPERATION_ENABLED, "Enable operation", 0x0237),
)}

#: The controlword-driven table: (state, command) -> transition number.
TRANSITIONS: dict[tuple[State, Command], int] = {
    (S.SWITCH_ON_DISABLED, Command.SHUTDOWN): 2,
    (S.READY_TO_SWITCH_ON, Command.SWITCH_ON): 3,
    (S.READY_TO_SWITCH_ON, Command.ENABLE_OPERATION): 3,   # §7.4.1 "3**"
    (S.SWITCHED_ON, Command.ENABLE_OPERATION): 4,
    (S.OPERATION_ENABLED, Command.SWITCH_ON): 5,
    (S.SWITCHED_ON, Command.SHUTDOWN): 6,
    (S.READY_TO_SWITCH_ON, Command.DISABLE_VOLTAGE): 7,
    (S.READY_TO_SWITCH_ON, Command.QUICK_STOP): 7,
    (S.OPERATION_ENABLED, Command.SHUTDOWN): 8,
    (S.OPERATION_ENABLED, Command.DISABLE_VOLTAGE): 9,
    (S.SWITCHED_ON, Command.DISABLE_VOLTAGE): 10,
    (S.SWITCHED_ON, Command.QUICK_STOP): 10,
    (S.OPERATION_ENABLED, Command.QUICK_STOP): 11,
    (S.QUICK_STOP_ACTIVE, Command.DISABLE_VOLTAGE): 12,
    (S.FAULT, Command.FAULT_RESET): 15,
    (S.QUICK_STOP_ACTIVE, Command.ENABLE_OPERATION): 16,
}

#: Transitions no controlword triggers (HCFA §7.2 "自然过渡").
AUTOMATIC_TRANSITIONS = frozenset({0, 1, 12, 13, 14})

#: Commands that keep a state as it is (a held level, not a refusal).
HOLDS: frozenset[tuple[State, Command]] = frozenset({
    (S.SWITCH_ON_DISABLED, Command.DISABLE_VOLTAGE),
    (S.SWITCH_ON_DISABLED, Command.QUICK_STOP),
    (S.READY_TO_SWITCH_ON, Command.SHUTDOWN),
    (S.SWITCHED_ON, Command.SWITCH_ON),
    (S.OPERATION_ENABLED, Command.ENABLE_OPERATION),
    (S.QUICK_STOP_ACTIVE, Command.QUICK_STOP),
})

#: Statusword mask and value of each state (HCFA §7.4.2, CiA 402).
STATE_MASKS: dict[State, tuple[int, int]] = {
    S.NOT_READY_TO_SWITCH_ON: (0x4F, 0x00), S.SWITCH_ON_DISABLED: (0x4F, 0x40),
    S.READY_TO_SWITCH_ON: (0x6F, 0x21), S.SWITCHED_ON: (0x6F, 0x23),
    S.OPERATION_ENABLED: (0x6F, 0x27), S.QUICK_STOP_ACTIVE: (0x6F, 0x07),
    S.FAULT_REACTION_ACTIVE: (0x4F, 0x0F), S.FAULT: (0x4F, 0x08),
}

#: Statusword per state with VE (bit 4) and remote (bit 9), HCFA §7.2.
STATUSWORD: dict[State, int] = {
    S.NOT_READY_TO_SWITCH_ON: 0x0000, S.SWITCH_ON_DISABLED: 0x0250,
    S.READY_TO_SWITCH_ON: 0x0231, S.SWITCHED_ON: 0x0233,
    S.OPERATION_ENABLED: 0x0237, S.QUICK_STOP_ACTIVE: 0x0217,
    S.FAULT_REACTION_ACTIVE: 0x021F, S.FAULT: 0x0218,
}

#: The per-mode idle statuswords of HCFA §7.3 (6061h = 1 PP, 3 PV, 6 HM, 8 CSP):
#: (mode, state) -> 6041h with the axis at rest and nothing started.
IDLE_STATUSWORD: dict[tuple[int, State], int] = {
    (1, S.SWITCH_ON_DISABLED): 0x0650, (1, S.READY_TO_SWITCH_ON): 0x0631,
    (1, S.SWITCHED_ON): 0x0633, (1, S.OPERATION_ENABLED): 0x8637, (1, S.FAULT): 0x0638,
    (3, S.SWITCH_ON_DISABLED): 0x0650, (3, S.READY_TO_SWITCH_ON): 0x0631,
    (3, S.SWITCHED_ON): 0x0633, (3, S.OPERATION_ENABLED): 0x0237, (3, S.FAULT): 0x0638,
    (6, S.SWITCH_ON_DISABLED): 0x0670, (6, S.READY_TO_SWITCH_ON): 0x0631,
    (6, S.SWITCHED_ON): 0x0633, (6, S.OPERATION_ENABLED): 0x8737, (6, S.FAULT): 0x0638,
    (8, S.READY_TO_SWITCH_ON): 0x0631, (8, S.SWITCHED_ON): 0x0633,
    (8, S.OPERATION_ENABLED): 0x1637,
}

#: Bits the mode layer owns in 6041h (8 and 10–15; HCFA §7.4.2, §7.5, §7.6).
MODE_BITS_MASK = 0xFD00


def state_of_statusword(sw: int) -> State:
    """The state a statusword shows, by the §7.4.2 masks."""
    for state, (mask, value) in STATE_MASKS.items():
        if sw & mask == value:
            return state
    raise Cia402Error(f"statusword 6041h = 0x{sw:04X} shows no state of HCFA §7.4.2")


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
                    limit_as_6085h: bool = True) -> QuickStopPlan:
    """The stop a quick stop performs for 605Ah = *option* (0–8).

    *limit_as_6085h*: the current/voltage-limit options 3/4/7/8 ramp on 6085h
    (a stepper has no torque-limited stop).  A ramp whose deceleration is 0 is
    undefined in the manual (6084h/6085h default 0, HCFA §8.3): the axis stops
    at once and the plan says so."""
    if option not in QUICK_STOP_OPTIONS:
        raise Cia402Error(
            f"605Ah quick-stop option code = {option} is not one of 0–8 "
            "(CiA 402; HCFA §8.3 gives no codes): SDO abort 0x06090030")
    ramp, then = QUICK_STOP_OPTIONS[option]
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
    sources: dict[str, str] = field(default_factory=dict)


PERSONALITIES: dict[str, Personality] = {
    "hcfa-am0520b": Personality(
        model="hcfa-am0520b", bit15="can-trigger",
        transition_16_options=frozenset({5, 6, 7, 8}),
        auto_qsa_to_sod_options=frozenset({0, 1, 2, 3, 4}),
        enable_from_ready="two-step", limit_stops_as_6085h=True,
        idle_statuswords=True, default_quick_stop_option=2,
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
        }),
    "kinco-servo": Personality(
        model="kinco-servo", bit15="reference-found",
        transition_16_options=frozenset({5, 6, 7, 8}),
        auto_qsa_to_sod_options=frozenset({0, 1, 2, 3, 4}),
        enable_from_ready="through", limit_stops_as_6085h=False,
        idle_statuswords=False, default_quick_stop_option=2,
        sources={
            "bit15": "Kinco §2.6: bit 15 Reference_Found, stays set once homed",
            "transition_16_options": "CiA 402-2 (Kinco seed silent)",
            "auto_qsa_to_sod_options": "CiA 402-2 (Kinco seed silent)",
            "enable_from_ready": "CiA 402-2: 3 then 4 in one evaluation (Kinco seed silent)",
            "limit_stops_as_6085h": "a servo stops at its current limit (CiA 402)",
            "idle_statuswords": "Kinco §2.6 gives the bits only, no per-mode values",
            "default_quick_stop_option": "CiA 402 default 2 (Kinco seed silent)",
        }),
}


def personality(model: str) -> Personality:
    """The personality of drive *model*; an unknown model is a located error."""
    try:
        return PERSONALITIES[model]
    except KeyError:
        raise Cia402Error(f"unknown CiA 402 drive model {model!r}; known: "
                          + ", ".join(sorted(PERSONALITIES))) from None


# --------------------------------------------------------------------------- the drive

ActionKind = Literal["power-on", "power-off", "quick-stop", "fault-reaction"]


@dataclass(frozen=True, slots=True)
class Action:
    """What the mode layer must do after a transition."""

    kind: ActionKind
    detail: str
    plan: QuickStopPlan | None = None


@dataclass(frozen=True, slots=True)
class Event:
    """One entry of the drive's event log; ``transition`` is None for a
    refused or ignored command, which then carries its explanation."""

    seq: int
    t: float
    transition: int | None
    source: str
    before: State
    after: State
    sw_before: int
    sw_after: int
    section: str
    note: str = ""

    def __str__(self) -> str:
        what = f"transition {self.transition}" if self.transition is not None else "no transition"
        return (f"#{self.seq} t={self.t:g}s {what} ({self.source}): {self.before} -> "
                f"{self.after}, 6041h 0x{self.sw_before:04X} -> 0x{self.sw_after:04X} "
                f"[{self.section}]" + (f" {self.note}" if self.note else ""))


@dataclass(frozen=True, slots=True)
class Result:
    """The outcome of one call: the transitions made, the actions for the mode
    layer and, when nothing changed, why (naming the steps and the manual §)."""

    command: Command | None
    events: tuple[Event, ...]
    actions: tuple[Action, ...]
    explanation: str
    state: State
    statusword: int

    @property
    def transitions(self) -> tuple[int, ...]:
        return tuple(e.transition for e in self.events if e.transition is not None)


#: The state each command leads to when it is followed step by step.
_COMMAND_GOAL: dict[Command, State] = {
    Command.SHUTDOWN: S.READY_TO_SWITCH_ON, Command.SWITCH_ON: S.SWITCHED_ON,
    Command.ENABLE_OPERATION: S.OPERATION_ENABLED, Command.DISABLE_VOLTAGE: S.SWITCH_ON_DISABLED,
    Command.QUICK_STOP: S.SWITCH_ON_DISABLED, Command.FAULT_RESET: S.SWITCH_ON_DISABLED,
}
_ORDER = (Command.SHUTDOWN, Command.SWITCH_ON, Command.ENABLE_OPERATION,
          Command.DISABLE_VOLTAGE, Command.QUICK_STOP, Command.FAULT_RESET)


def command_path(start: State, goal: State) -> list[tuple[Command, int]]:
    """The shortest controlword route from *start* to *goal* (command, transition)."""
    seen = {start}
    queue: deque[tuple[State, list[tuple[Command, int]]]] = deque([(start, [])])
    while queue:
        state, path = queue.popleft()
        if state is goal:
            return path
        for cmd in _ORDER:
            n = TRANSITIONS.get((state, cmd))
            if n is None or n == 16:
                continue
            nxt = TRANSITION_ROWS[n].target
            if nxt not in seen:
                seen.add(nxt)
                queue.append((nxt, path + [(cmd, n)]))
    return []


def _steps(path: list[tuple[Command, int]]) -> str:
    return ", then ".join(f"0x{COMMAND_WORD[c]:04X} {c} ({n})" for c, n in path)


class Drive402:
    """One drive's CiA 402 power state machine with its event log.

    Inputs are controlwords (:meth:`apply_controlword`), drive cycles
    (:meth:`cycle`), faults (:meth:`raise_fault`) and the axis coming to rest
    (:meth:`motion_stopped`); each returns a :class:`Result`.  Parameters the
    state machine reads are plain attributes the object dictionary sets:
    ``quick_stop_option`` (605Ah), ``dec_6084``, ``dec_6085`` and ``mode``
    (6061h, None = no mode shown)."""

    def __init__(self, model: str = "hcfa-am0520b", t: float = 0.0,
                 mode: int | None = None, power_on: bool = True) -> None:
        self.personality = personality(model)
        self.state = S.NOT_READY_TO_SWITCH_ON
        self.controlword = 0
        self.log: list[Event] = []
        self.quick_stop_option = self.personality.default_quick_stop_option
        self.dec_6084 = 0
        self.dec_6085 = 0
        self.mode = mode
        self.voltage_present = True
        self.homed = False
        self.error_code = 0          # 603Fh
        self.error_register = 0      # 1001h
        self.fault: FaultCode | None = None
        self.fault_why = ""
        self.fault_cause_active = False
        self.quick_stop: QuickStopPlan | None = None
        self.at_rest_in_quick_stop = False
        self._mode_bits: int | None = None
        if power_on:
            self.power_on(t)

    # ---------------------------------------------------------------- statusword
    @property
    def statusword(self) -> int:
        """6041h: the state's word (HCFA §7.2), the idle mode bits of §7.3 or
        the mode layer's bits, bit 10 at rest in QSA, Kinco's bit 15."""
        if self.state is S.NOT_READY_TO_SWITCH_ON:
            return 0
        base = STATUSWORD[self.state]
        if self._mode_bits is not None:
            extra = self._mode_bits
        elif self.personality.idle_statuswords and self.mode is not None:
            extra = IDLE_STATUSWORD.get((self.mode, self.state), base) & ~base
        else:
            extra = 0
        if self.state is S.QUICK_STOP_ACTIVE and self.at_rest_in_quick_stop:
            extra |= 0x0400
        if self.personality.bit15 == "reference-found":
            extra = (extra & ~0x8000) | (0x8000 if self.homed else 0)
        sw = base | extra
        return sw if self.voltage_present else sw & ~0x0010

    def set_mode_bits(self, bits: int) -> None:
        """Set 6041h bits 8 and 10–15 for the active mode (HCFA §7.5, §7.6);
        they fall back to the idle values at the next transition."""
        if bits & ~MODE_BITS_MASK:
            raise Cia402Error(f"mode bits 0x{bits:04X} touch state bits of 6041h; only "
                              f"bits 8 and 10–15 (0x{MODE_BITS_MASK:04X}) belong to a mode "
                              "(HCFA §7.4.2)")
        self._mode_bits = bits

    @property
    def operation_enabled(self) -> bool:
        """The drive follows its mode (OE, or QSA while stopping)."""
        return self.state in (S.OPERATION_ENABLED, S.QUICK_STOP_ACTIVE)

    # ---------------------------------------------------------------- inputs
    def power_on(self, t: float, fault: tuple[int, int | None, str] | None = None) -> Result:
        """Transitions 0 and 1 (HCFA §7.2); with *fault* (603Fh, alarm, why)
        found during initialisation, 13 replaces 1."""
        ev = [self._enter(0, "power-on", t)]
        if fault is None:
            ev.append(self._enter(1, "initialisation done", t))
            return self._result(None, ev, [], "")
        res = self.raise_fault(*fault, t=t)
        return self._result(None, ev + list(res.events), list(res.actions), "")

    def power_cycle(self, t: float) -> Result:
        """Switch the control power off and on: faults that only a power
        cycle clears (HCFA §4.7 "否") are gone, 1001h/603Fh read 0."""
        self.state = S.NOT_READY_TO_SWITCH_ON
        self.controlword = 0
        self.error_code = self.error_register = 0
        self.fault, self.fault_why, self.fault_cause_active = None, "", False
        self.quick_stop, self.at_rest_in_quick_stop, self._mode_bits = None, False, None
        return self.power_on(t)

    def apply_controlword(self, cw: int, t: float) -> Result:
        """Write 6040h = *cw* at time *t* and evaluate it (one drive cycle)."""
        cmd = decode_controlword(cw, self.controlword)
        new = cw != self.controlword
        self.controlword = cw
        return self._evaluate(cmd, t, f"6040h = 0x{cw:04X}", log_refusal=new)

    def cycle(self, t: float) -> Result:
        """One drive cycle with the controlword held: levels are evaluated
        again (HCFA §7.4.1) and a fault reaction completes (14)."""
        cmd = decode_controlword(self.controlword, self.controlword)
        return self._evaluate(cmd, t, f"6040h = 0x{self.controlword:04X} held",
                              log_refusal=False)

    def command(self, cmd: Command, t: float, source: str) -> Result:
        """Apply *cmd* on the drive's own account (e.g. the EtherCAT bus
        leaving OP), without changing the held controlword."""
        return self._evaluate(cmd, t, source, log_refusal=True)

    def motion_stopped(self, t: float) -> Result:
        """The mode layer reports the axis at rest after a quick stop: with
        605Ah 0–4 the drive goes to SWITCH ON DISABLED (12), with 5–8 it stays
        in QUICK STOP ACTIVE with bit 10 set."""
        if self.state is not S.QUICK_STOP_ACTIVE or self.quick_stop is None:
            return self._result(None, [], [], f"no quick stop in progress in {self.state}")
        return self._result(None, self._stopped(t), [], "")

    def raise_fault(self, code: int, alarm: int | None, why: str, t: float,
                    cause_active: bool = False) -> Result:
        """A fault: 603Fh = *code*, 1001h bit 0, transition 13 (HCFA §4.7, §7.2).

        *cause_active*: the cause persists (e.g. bus over-voltage) and a fault
        reset is refused until :meth:`clear_fault_cause`."""
        fc = FAULT_CODES.get(code)
        if fc is None:
            known = ", ".join(f"{c} ({f.name})" for c, f in FAULT_CODES.items())
            raise Cia402Error(f"603Fh error code {code} (0x{code:04X}) is not in the "
                              f"HCFA §4.7 table nor a modelled CiA 402 code; known: {known}")
        if alarm != fc.alarm:
            raise Cia402Error(f"603Fh = {code} is alarm {fc.alarm} ({fc.name}, {fc.section}), "
                              f"not alarm {alarm}")
        self.error_code, self.error_register = code, self.error_register | 0x01
        self.fault, self.fault_why, self.fault_cause_active = fc, why, cause_active
        source = f"fault 603Fh = {code} (0x{code:04X}) {fc.name}: {why}"
        if self.state in (S.FAULT_REACTION_ACTIVE, S.FAULT):
            ev = self._log(None, source, t, self.state, self.statusword, fc.section,
                           f"already in {self.state}; 603Fh now reads {code}")
            return self._result(None, [ev], [], f"already in {self.state}: 603Fh = {code}")
        ev = self._enter(13, source, t)
        act = Action("fault-reaction", f"{fc.name}: the axis is switched off ({fc.section}; "
                     "605Eh is not in the manual, the reaction lasts one drive cycle)")
        return self._result(None, [ev], [act], "")

    def clear_fault_cause(self) -> None:
        """The fault's cause is gone; a fault reset may now clear it."""
        self.fault_cause_active = False

    # ---------------------------------------------------------------- engine
    def _evaluate(self, cmd: Command, t: float, source: str, log_refusal: bool) -> Result:
        events: list[Event] = []
        actions: list[Action] = []
        explanation = ""
        state = self.state
        n = TRANSITIONS.get((state, cmd))
        refusal = self._guard(state, cmd, n)
        if refusal is None and n is not None:
            events.append(self._enter(n, source, t))
            actions += self._actions(n, t, events)
            if n == 3 and cmd is Command.ENABLE_OPERATION \
                    and self.personality.enable_from_ready == "through":
                events.append(self._enter(4, source, t, "CiA 402: Enable operation goes on"))
                actions += self._actions(4, t, events)
        elif (state, cmd) in HOLDS:
            explanation = f"{cmd} holds {state} (HCFA §7.4.1)"
        else:
            explanation = refusal or self._explain(state, cmd)
            if log_refusal:
                events.append(self._log(None, source, t, state, self.statusword,
                                        "HCFA §7.2, §7.4.1", explanation))
        if self.state is S.FAULT_REACTION_ACTIVE and state is S.FAULT_REACTION_ACTIVE:
            events.append(self._enter(14, "fault reaction done", t))
        return self._result(cmd, events, actions, explanation)

    def _guard(self, state: State, cmd: Command, n: int | None) -> str | None:
        if n == 15 and self.fault is not None:
            fc = self.fault
            if not fc.resettable:
                return (f"Fault reset refused: 603Fh = {fc.code} ({fc.name}) is cleared by a "
                        f"power cycle only ({fc.section}: reset '否')")
            if self.fault_cause_active:
                return (f"Fault reset refused: the cause of 603Fh = {fc.code} ({fc.name}) is "
                        f"still present ({self.fault_why}); {fc.section}")
        if n == 16 and self.quick_stop_option not in self.personality.transition_16_options:
            return (f"Enable operation (0x000F) in QUICK STOP ACTIVE is transition 16, allowed "
                    f"only with 605Ah in 5–8 (CiA 402-2; HCFA §7.2 row 16); 605Ah = "
                    f"{self.quick_stop_option}, so the drive goes to SWITCH ON DISABLED by itself "
                    "once at rest (12); then 0x0006, 0x0007, 0x000F")
        return None

    def _explain(self, state: State, cmd: Command) -> str:
        cw = COMMAND_WORD.get(cmd)
        what = f"{cmd} (0x{cw:04X})" if cw is not None else str(cmd)
        if cmd is Command.NONE:
            return ("no command: bit 7 (fault reset) is held at 1 and only its 0->1 edge acts; "
                    "no other command matches until it returns to 0 (HCFA §7.4.1)")
        if state is S.NOT_READY_TO_SWITCH_ON:
            return (f"{what} ignored: the drive is initialising and reaches SWITCH ON "
                    "DISABLED by itself (transition 1, HCFA §7.2)")
        if state is S.FAULT_REACTION_ACTIVE:
            return (f"{what} ignored: FAULT REACTION ACTIVE ends by itself in FAULT "
                    "(transition 14, HCFA §7.2); then a 0->1 edge of bit 7 (0x0080) resets (15)")
        if cmd is Command.FAULT_RESET:
            return (f"Fault reset (bit 7 0->1) has no effect in {state}: there is no fault "
                    "(603Fh = 0); it acts only in FAULT (transition 15, HCFA §7.2, §7.4.1)")
        if state is S.FAULT:
            rest = command_path(S.SWITCH_ON_DISABLED, _COMMAND_GOAL[cmd])
            then = f", then {_steps(rest)}" if rest else ""
            return (f"{what} refused in FAULT (603Fh = {self.error_code}): FAULT is left only "
                    f"by a 0->1 edge of bit 7, 0x0080 Fault reset (15){then} (HCFA §7.2, §7.4.1)")
        if state is S.QUICK_STOP_ACTIVE:
            rest = command_path(S.SWITCH_ON_DISABLED, _COMMAND_GOAL[cmd])
            return (f"{what} refused in QUICK STOP ACTIVE: it is left by 0x0000 Disable voltage "
                    f"(12), by itself once at rest when 605Ah is 0–4, or by 0x000F Enable "
                    f"operation (16) when 605Ah is 5–8 (605Ah = {self.quick_stop_option}); from "
                    f"SWITCH ON DISABLED: {_steps(rest)} (HCFA §7.2)")
        path = command_path(state, _COMMAND_GOAL[cmd])
        return (f"{what} is no transition from {state} (HCFA §7.2, §7.4.1): first "
                f"{_steps(path)}")

    def _actions(self, n: int, t: float, events: list[Event]) -> list[Action]:
        if n in (4, 16):
            self.quick_stop, self.at_rest_in_quick_stop = None, False
            return [Action("power-on", "operation enabled: the mode runs (HCFA §7.2)")]
        if n in (5, 8, 9):
            return [Action("power-off", f"transition {n}: the drive function is disabled at "
                           "once (605Bh/605Ch are not in the manual)")]
        if n == 12:
            self.quick_stop, self.at_rest_in_quick_stop = None, False
            return [Action("power-off", "quick stop ended: SWITCH ON DISABLED (HCFA §7.2)")]
        if n == 11:
            plan = quick_stop_plan(self.quick_stop_option, self.dec_6084, self.dec_6085,
                                   self.personality.limit_stops_as_6085h)
            self.quick_stop, self.at_rest_in_quick_stop = plan, False
            acts = [Action("quick-stop", plan.explanation, plan)]
            if plan.ramp == "none" or plan.deceleration == 0 and plan.ramp in ("6084h", "6085h"):
                events += self._stopped(t)
            return acts
        if n == 15:
            self.error_code, self.error_register = 0, self.error_register & ~0x01
            self.fault, self.fault_why = None, ""
        return []

    def _stopped(self, t: float) -> list[Event]:
        plan = self.quick_stop
        assert plan is not None
        if plan.then is S.SWITCH_ON_DISABLED:
            ev = self._enter(12, f"at rest after quick stop (605Ah = {plan.option})", t)
            self.quick_stop, self.at_rest_in_quick_stop = None, False
            return [ev]
        sw = self.statusword
        self.at_rest_in_quick_stop = True
        return [self._log(None, f"at rest after quick stop (605Ah = {plan.option})", t,
                          self.state, sw, "CiA 402 605Ah 5–8",
                          "stays in QUICK STOP ACTIVE; bit 10 set")]

    def _enter(self, n: int, source: str, t: float, note: str = "") -> Event:
        row = TRANSITION_ROWS[n]
        before, sw_before = self.state, self.statusword
        if row.source is not None and row.source is not before:
            raise AssertionError(f"transition {n} from {before}")
        self.state = row.target
        self._mode_bits = None
        return self._log(n, source, t, before, sw_before, row.section, note)

    def _log(self, n: int | None, source: str, t: float, before: State, sw_before: int,
             section: str, note: str = "") -> Event:
        ev = Event(len(self.log) + 1, t, n, source, before, self.state, sw_before,
                   self.statusword, section, note)
        self.log.append(ev)
        return ev

    def _result(self, cmd: Command | None, events: list[Event], actions: list[Action],
                explanation: str) -> Result:
        return Result(cmd, tuple(events), tuple(actions), explanation, self.state,
                      self.statusword)
