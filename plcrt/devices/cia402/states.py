"""The CiA 402 power states, controlword commands and transition table as
data (HCFA §7.2, §7.3, §7.4.1, §7.4.2).

What it is: the eight states, the command decode of 6040h (levels of bits 0–3,
the rising edge of bit 7), transitions 0–16 as rows citing the manual, the
``(state, command) -> transition`` table, the holding commands, the statusword
masks and HCFA's statusword values per state and per mode.

What it is not: no behaviour beyond decoding; :mod:`.statemachine` runs the
table, :mod:`.reactions` holds quick stop, faults and the drive personalities.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from ...errors import PlcConfigError

__all__ = [
    "Cia402Error", "State", "Command", "COMMAND_WORD", "decode_controlword", "Transition",
    "TRANSITION_ROWS", "TRANSITIONS", "AUTOMATIC_TRANSITIONS", "HOLDS", "STATE_MASKS",
    "STATUSWORD", "IDLE_STATUSWORD", "MODE_BITS_MASK", "state_of_statusword",
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
