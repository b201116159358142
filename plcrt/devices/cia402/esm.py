"""The EtherCAT state machine (ESM) of a CoE drive (HCFA §6.5; ETG behaviour
as SOES ``ESC_state``; AL status codes as SOEM ``ethercatprint.c``).

What it is: INIT -> PRE-OP -> SAFE-OP -> OP requested through AL Control
(0x0120: state in bits 0–3, error acknowledge in bit 4) and reported in AL
Status (0x0130: state, error flag in bit 4) with the AL Status Code (0x0134).
Upward steps go one at a time, downward ones may skip; a refused request sets
the error flag and names its AL code; while the flag is set, requests without
the acknowledge bit are ignored.  PRE-OP -> SAFE-OP checks the PDO
assignment/mapping through an injected validator, so this module does not
depend on the object dictionary.

What it is not: no frames, no mailbox, no timing.  A bad mapping is returned
as a fault (603Fh = 35) for the caller to raise on the CiA 402 state machine,
and leaving OP is reported (``left_op``) so the caller can take the drive out
of OPERATION ENABLED.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import Callable, Literal

from .statemachine import Cia402Error

__all__ = ["EsmState", "AL_CODES", "MappingProblem", "AlResult", "Esm", "EsmEvent"]


class EsmState(IntEnum):
    """AL states as coded in AL Control / AL Status (ETG.1000.6)."""

    INIT = 1
    PREOP = 2
    BOOT = 3
    SAFEOP = 4
    OP = 8


#: AL status codes a drive simulation uses (digest §6.2, SOEM ethercatprint.c).
AL_CODES: dict[int, str] = {
    0x0000: "no error", 0x0001: "unspecified error",
    0x0011: "invalid requested state change", 0x0012: "unknown requested state",
    0x0016: "invalid mailbox configuration (PREOP)", 0x0017: "invalid sync manager configuration",
    0x0018: "no valid inputs available", 0x0019: "no valid outputs",
    0x001A: "synchronisation error", 0x001B: "sync manager watchdog",
    0x001D: "invalid output configuration", 0x001E: "invalid input configuration",
    0x001F: "invalid watchdog configuration", 0x0024: "invalid input mapping",
    0x0025: "invalid output mapping", 0x002C: "fatal sync error",
    0x0030: "invalid DC SYNC configuration", 0x0034: "DC sync timeout",
    0x0035: "DC invalid sync cycle time", 0x0036: "DC invalid SYNC0 cycle time",
}


@dataclass(frozen=True, slots=True)
class MappingProblem:
    """A validator's finding: which sync manager side is wrong, and why."""

    side: Literal["outputs", "inputs"]   # outputs = RxPDO / SM2, inputs = TxPDO / SM3
    explanation: str


#: The validator: None when the assignment/mapping is good (it then takes effect).
Validator = Callable[[], "MappingProblem | None"]
#: Checks at SAFE-OP -> OP: None, or why the outputs are not valid (AL 0x0019).
OutputsCheck = Callable[[], "str | None"]
#: Checks at PRE-OP -> SAFE-OP: None, or (AL code, why) for a sync cycle the
#: drive cannot take (0x0035 / 0x0036, HCFA §7.4.3; see sync.py).
SyncCheck = Callable[[], "tuple[int, str] | None"]


@dataclass(frozen=True, slots=True)
class EsmEvent:
    """One entry of the ESM log."""

    seq: int
    t: float
    request: int            # the AL Control value, or -1 for an internal event
    before: EsmState
    after: EsmState
    al_code: int
    error: bool
    explanation: str


@dataclass(frozen=True, slots=True)
class AlResult:
    """The outcome of an AL Control write or an ESM event."""

    accepted: bool
    state: EsmState
    al_status: int           # register 0x0130
    al_code: int             # register 0x0134
    explanation: str
    fault: tuple[int, int, str] | None = None   # (603Fh, alarm, why) to raise
    left_op: bool = False


_NAMES = {EsmState.INIT: "INIT", EsmState.PREOP: "PRE-OP", EsmState.BOOT: "BOOT",
          EsmState.SAFEOP: "SAFE-OP", EsmState.OP: "OP"}
_UP = (EsmState.INIT, EsmState.PREOP, EsmState.SAFEOP, EsmState.OP)


class Esm:
    """One slave's ESM.  *validate_mapping* is called at PRE-OP -> SAFE-OP;
    *check_outputs* (optional) at SAFE-OP -> OP."""

    def __init__(self, validate_mapping: Validator,
                 check_outputs: OutputsCheck | None = None,
                 check_sync: SyncCheck | None = None) -> None:
        self.validate_mapping = validate_mapping
        self.check_outputs = check_outputs
        self.check_sync = check_sync
        self.state = EsmState.INIT
        self.error = False
        self.al_code = 0
        self.log: list[EsmEvent] = []

    @property
    def al_status(self) -> int:
        """AL Status 0x0130: the state, bit 4 = error indication."""
        return int(self.state) | (0x10 if self.error else 0)

    @property
    def mailbox(self) -> bool:
        """SDO and EMCY work (PRE-OP and above, HCFA §6.5)."""
        return self.state in (EsmState.PREOP, EsmState.SAFEOP, EsmState.OP)

    @property
    def inputs(self) -> bool:
        """TxPDOs are sent (SAFE-OP and OP)."""
        return self.state in (EsmState.SAFEOP, EsmState.OP)

    @property
    def outputs(self) -> bool:
        """RxPDOs act (OP only)."""
        return self.state is EsmState.OP

    def request(self, state: EsmState | int, t: float = 0.0, ack: bool = False) -> AlResult:
        """Write AL Control with the requested *state* (and the ack bit)."""
        if not 0 <= int(state) <= 0x0F:
            raise Cia402Error(f"requested AL state {int(state)} does not fit AL Control "
                              "bits 0–3 (ETG.1000.6)")
        return self.write_al_control(int(state) | (0x10 if ack else 0), t)

    def write_al_control(self, value: int, t: float = 0.0) -> AlResult:
        """Write AL Control 0x0120 = *value* (bits 0–3 state, bit 4 ack)."""
        if not 0 <= value <= 0xFFFF:
            raise Cia402Error(f"AL Control 0x0120 = {value} is not a 16-bit value")
        want, ack = value & 0x0F, bool(value & 0x10)
        before = self.state
        if self.error and not ack:
            return self._done(value, t, before, False,
                              f"AL Control 0x{value:04X} ignored: the error flag is set "
                              f"(AL Status Code 0x{self.al_code:04X} "
                              f"{AL_CODES.get(self.al_code, '')}); acknowledge with bit 4 "
                              "(ETG.1000.6, SOES ESC_state)", log=True)
        if ack:
            self.error, self.al_code = False, 0
        if want not in {int(s) for s in EsmState}:
            return self._refuse(value, t, 0x0012, f"requested state {want} is not an AL state "
                                "(1 INIT, 2 PRE-OP, 3 BOOT, 4 SAFE-OP, 8 OP)")
        target = EsmState(want)
        name = f"{_NAMES[before]} -> {_NAMES[target]}"
        if target is before:
            return self._done(value, t, before, True, f"already in {_NAMES[before]}", log=ack)
        if EsmState.BOOT in (before, target):
            if {before, target} == {EsmState.INIT, EsmState.BOOT}:
                return self._go(value, t, target, f"{name}")
            return self._refuse(value, t, 0x0011, f"{name}: BOOT is reached from and left to "
                                "INIT only (ETG.1000.6)")
        if _UP.index(target) > _UP.index(before) + 1:
            steps = " -> ".join(_NAMES[s] for s in _UP[_UP.index(before):_UP.index(target) + 1])
            return self._refuse(value, t, 0x0011, f"{name} skips a state: upward transitions go "
                                f"one at a time, {steps} (HCFA §6.5 rule 1)")
        if before is EsmState.PREOP and target is EsmState.SAFEOP:
            bad_sync = self.check_sync() if self.check_sync else None
            if bad_sync is not None:
                code, why = bad_sync
                return self._refuse(value, t, code, f"{name} refused: {AL_CODES[code]}: {why}")
            problem = self.validate_mapping()
            if problem is not None:
                code = 0x001D if problem.side == "outputs" else 0x001E
                why = (f"{name} refused: {AL_CODES[code]}: {problem.explanation}; "
                       "fault 603Fh = 35 PDO mapping error (HCFA §4.7, §6.7)")
                res = self._refuse(value, t, code, why)
                return AlResult(False, res.state, res.al_status, res.al_code, why,
                                fault=(35, 35, problem.explanation))
        if before is EsmState.SAFEOP and target is EsmState.OP and self.check_outputs:
            why = self.check_outputs()
            if why is not None:
                return self._refuse(value, t, 0x0019, f"{name} refused: no valid outputs: {why}")
        return self._go(value, t, target, name)

    def sm_watchdog(self, t: float = 0.0) -> AlResult:
        """The SM2 watchdog expired in OP: SAFE-OP with the error flag, AL
        0x001B, and alarm 17 for the drive (digest §5, §6.1)."""
        if self.state is not EsmState.OP:
            return self._done(-1, t, self.state, False,
                              f"SM watchdog ignored in {_NAMES[self.state]}: it acts in OP only",
                              log=False)
        why = "SM2 watchdog expired: no process data from the master"
        before = self.state
        self.state, self.error, self.al_code = EsmState.SAFEOP, True, 0x001B
        self._log(-1, t, before, why)
        return AlResult(False, self.state, self.al_status, self.al_code,
                        f"OP -> SAFE-OP: {AL_CODES[0x001B]}; {why}",
                        fault=(17, 17, why), left_op=True)

    # ---------------------------------------------------------------- helpers
    def _go(self, value: int, t: float, target: EsmState, name: str) -> AlResult:
        before = self.state
        self.state = target
        left = before is EsmState.OP
        why = name + ("; outputs stop, the drive leaves OPERATION ENABLED" if left else "")
        self._log(value, t, before, why)
        return AlResult(True, self.state, self.al_status, self.al_code, why, left_op=left)

    def _refuse(self, value: int, t: float, code: int, why: str) -> AlResult:
        self.error, self.al_code = True, code
        text = f"AL Status Code 0x{code:04X} ({AL_CODES[code]}): {why}"
        self._log(value, t, self.state, text)
        return AlResult(False, self.state, self.al_status, code, text)

    def _done(self, value: int, t: float, before: EsmState, ok: bool, why: str,
              log: bool) -> AlResult:
        if log:
            self._log(value, t, before, why)
        return AlResult(ok, self.state, self.al_status, self.al_code, why)

    def _log(self, value: int, t: float, before: EsmState, why: str) -> None:
        self.log.append(EsmEvent(len(self.log) + 1, t, value, before, self.state,
                                 self.al_code, self.error, why))
