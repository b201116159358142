"""The CiA 402 power state machine of a bus drive (HCFA §7.2–§7.4, §4.7).

What it is: :class:`Drive402`, which runs the tables of :mod:`.states`
(transitions 0–16, controlword 6040h decoded as levels with fault reset on the
rising edge of bit 7, statusword 6041h per state and mode) and of
:mod:`.reactions` (quick stop per 605Ah, 603Fh faults, the model's
personality).  It applies controlwords, cycles and faults and keeps a numbered
event log in which every command that changes nothing is explained with the
steps it needs and the manual section.  All those tables are re-exported here.

What it is not: it has no clock and no motion.  Time is a number the caller
passes in and only recorded; a quick stop or a fault reaction is returned as an
:class:`Action` for the mode layer to carry out, which then reports the axis at
rest with :meth:`Drive402.motion_stopped`.  Modes set the mode-specific
statusword bits (8, 10–15) through :meth:`Drive402.set_mode_bits`.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import Literal

from .reactions import (FAULT_CODES, PERSONALITIES, QUICK_STOP_OPTIONS, FaultCode,
                        Personality, QuickStopPlan, personality, quick_stop_plan)
from .states import (AUTOMATIC_TRANSITIONS, COMMAND_WORD, HOLDS, IDLE_STATUSWORD,
                     MODE_BITS_MASK, STATE_MASKS, STATUSWORD, TRANSITION_ROWS, TRANSITIONS,
                     Cia402Error, Command, State, Transition, decode_controlword,
                     state_of_statusword)

__all__ = [
    # re-exported tables (states, reactions)
    "State", "Command", "COMMAND_WORD", "Transition", "TRANSITION_ROWS", "TRANSITIONS",
    "AUTOMATIC_TRANSITIONS", "HOLDS", "STATE_MASKS", "STATUSWORD", "IDLE_STATUSWORD",
    "MODE_BITS_MASK", "decode_controlword", "state_of_statusword", "Cia402Error",
    "QuickStopPlan", "QUICK_STOP_OPTIONS", "quick_stop_plan", "FaultCode", "FAULT_CODES",
    "Personality", "PERSONALITIES", "personality",
    # the drive
    "Action", "Event", "Result", "command_path", "Drive402",
]

S = State
# perf: members read on every bus cycle, as module constants (an Enum class
# attribute goes through EnumType.__getattr__ on Python 3.11)
_NOT_READY, _QSA, _FRA = S.NOT_READY_TO_SWITCH_ON, S.QUICK_STOP_ACTIVE, S.FAULT_REACTION_ACTIVE

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
    command: Command | None = None   # the decoded controlword, if one caused it

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
        self._quick_stop_option = self.personality.default_quick_stop_option
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

    @property
    def quick_stop_option(self) -> int:
        """605Ah, the quick-stop option code (0–8)."""
        return self._quick_stop_option

    @quick_stop_option.setter
    def quick_stop_option(self, option: int) -> None:
        if option not in QUICK_STOP_OPTIONS:
            raise Cia402Error(
                f"605Ah quick-stop option code = {option} is not one of 0–8 "
                "(CiA 402; HCFA §8.3 gives no codes): SDO abort 0x06090030")
        self._quick_stop_option = option

    # ---------------------------------------------------------------- statusword
    @property
    def statusword(self) -> int:
        """6041h: the state's word (HCFA §7.2), the idle mode bits of §7.3 or
        the mode layer's bits, bit 10 at rest in QSA, Kinco's bit 15."""
        if self.state is _NOT_READY:
            return 0
        base = STATUSWORD[self.state]
        if self._mode_bits is not None:
            extra = self._mode_bits
        elif self.personality.idle_statuswords and self.mode is not None:
            extra = IDLE_STATUSWORD.get((self.mode, self.state), base) & ~base
        else:
            extra = 0
        if self.state is _QSA and self.at_rest_in_quick_stop:
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

    def cycle_acts(self) -> bool:
        """Whether :meth:`cycle` would change anything now: a transition the
        held controlword makes, or the end of a fault reaction (14).  A held
        level that holds its state or is refused changes nothing (a cycle
        logs no refusal), so a caller may skip that cycle."""
        # perf: the bus cycle asks this first; :meth:`cycle` builds the
        # explanation of a refusal and a Result, which nobody reads then
        state = self.state
        if state is _FRA:
            return True
        cw = self.controlword
        cmd = decode_controlword(cw, cw)
        n = TRANSITIONS.get((state, cmd))
        return n is not None and self._guard(state, cmd, n) is None

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
        self.quick_stop, self.at_rest_in_quick_stop = None, False
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
            events.append(self._enter(n, source, t, cmd=cmd))
            actions += self._actions(n, t, events)
            if n == 3 and cmd is Command.ENABLE_OPERATION \
                    and self.personality.enable_from_ready == "through":
                events.append(self._enter(4, source, t, "CiA 402: Enable operation goes on",
                                          cmd=cmd))
                actions += self._actions(4, t, events)
        elif (state, cmd) in HOLDS:
            explanation = f"{cmd} holds {state} (HCFA §7.4.1)"
        else:
            explanation = refusal or self._explain(state, cmd, source)
            if log_refusal:
                events.append(self._log(None, source, t, state, self.statusword,
                                        "HCFA §7.2, §7.4.1", explanation, cmd))
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

    def _explain(self, state: State, cmd: Command, source: str) -> str:
        what = f"{cmd} ({source})"
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
            fc = self.fault
            if fc is not None and not fc.resettable:
                return (f"{what} refused in FAULT (603Fh = {fc.code}, {fc.name}): only a power "
                        f"cycle clears it ({fc.section}: reset '否'){then}")
            cause = (f"once its cause is gone ({self.fault_why}), "
                     if fc is not None and self.fault_cause_active else "")
            return (f"{what} refused in FAULT (603Fh = {self.error_code}): FAULT is left only "
                    f"{cause}by a 0->1 edge of bit 7, 0x0080 Fault reset (15){then} "
                    "(HCFA §7.2, §7.4.1)")
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
            p = self.personality
            plan = quick_stop_plan(self.quick_stop_option, self.dec_6084, self.dec_6085,
                                   p.limit_stops_as_6085h, p.auto_qsa_to_sod_options)
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

    def _enter(self, n: int, source: str, t: float, note: str = "",
               cmd: Command | None = None) -> Event:
        row = TRANSITION_ROWS[n]
        before, sw_before = self.state, self.statusword
        if row.source is not None and row.source is not before:
            raise AssertionError(f"transition {n} from {before}")
        self.state = row.target
        self._mode_bits = None
        return self._log(n, source, t, before, sw_before, row.section, note, cmd)

    def _log(self, n: int | None, source: str, t: float, before: State, sw_before: int,
             section: str, note: str = "", cmd: Command | None = None) -> Event:
        ev = Event(len(self.log) + 1, t, n, source, before, self.state, sw_before,
                   self.statusword, section, note, cmd)
        self.log.append(ev)
        return ev

    def _result(self, cmd: Command | None, events: list[Event], actions: list[Action],
                explanation: str) -> Result:
        return Result(cmd, tuple(events), tuple(actions), explanation, self.state,
                      self.statusword)
