"""Write the wizard sections of small test projects (what follows the CPU
name in a Micro/WIN V4 or SMART V2 project), laid out as
:mod:`plcrt.project.wizards` reads them (docs/project-files.md, "Wizards").

:func:`wizard_tail` is what :func:`project_writer.stream` writes after the
CPU name; :func:`pto_record` (V4) and :func:`smart_lists` (SMART) give it
configurations.  A test helper, not part of plcrt.
"""

from __future__ import annotations

import struct

from project_writer import strl, u1, u2, u4


def f4(v: float) -> bytes: return struct.pack("<f", v)
def f8(v: float) -> bytes: return struct.pack("<d", v)


#: the rest of the CPU section: its version (empty), no feature bytes
CPU_REST = u1(0) + strl("") + u2(0) + u1(0)
#: a V4 project's last section: its name, a digest, 16 zero bytes
PROJECT_INFO = u1(0) + strl("") + u2(0) + u1(1) + u4(0) + bytes(16) + u1(1) + bytes(4)


def v4_header(ident: int, name: str, page: str, memory: int) -> bytes:
    """A V4 wizard record's header: id, version 5, names, VB memory, time stamps."""
    return (u2(ident) + u1(5) + strl(name) + strl(page) + strl(name + "_SYM")
            + u2(2) + u2(0x1002) + u2(0) + u1(0) + u4(memory) + bytes(32))


def pto_record(output: int = 0, *, max_speed: float = 20000.0, min_speed: float = 16.0,
               ss_speed: float = 200.0, accel_ms: int = 500, decel_ms: int = 500,
               memory: int = 500, prefix: str | None = None) -> bytes:
    """The Position Control wizard's record for Q0.``output`` (its head, as
    described, and 64 bytes standing for the undescribed rest)."""
    name = prefix or f"PTO{output}"
    subs = [f"{name}_{k}" for k in ("CTRL", "MAN", "RUN", "LDPOS", "ADV")]
    return (v4_header(0x84, name, f"{name}_DATA", memory) + u4(output) + u4(1) + u4(0)
            + f8(max_speed) + f8(min_speed) + f8(ss_speed) + u4(0) + u4(0) + u4(accel_ms)
            + u4(decel_ms) + u4(0) + u1(1) + b"".join(strl(s) for s in subs)
            + b"\x5a" * 64)


def pid_record_v4(loop: int = 0, memory: int = 300, sample_s: float = 0.1) -> bytes:
    """A V4 PID wizard record for loop ``loop`` (its described fields)."""
    return (v4_header(0x02, f"PID{loop}", f"PID{loop}_DATA", memory) + u1(2) + u4(loop)
            + u1(1) + f4(1.0) + f4(0.0) + f4(sample_s) + b"\x33" * 20 + f4(0.0) + u4(0)
            + u4(32000) + f4(0.0) + f4(1.0) + (u1(0) + f4(0.0)) * 2 + u1(0) + u2(0) + u1(0)
            + strl(f"PID{loop}_INIT", 1) + strl("PID_EXE", 1) + bytes(75))


def position_record(module: int = 0, memory: int = 700) -> bytes:
    """A V4 EM253 Position Control wizard record (its described fields)."""
    subs = ["CTRL", "MAN", "GOTO", "RUN", "RSEEK", "LDOFF", "LDPOS", "SRATE", "DIS", "CLR",
            "CFG"]
    return (v4_header(0x10, f"POS{module}", f"POS{module}_DATA", memory) + u1(0) + u1(module)
            + bytes(2 + 1 + 4 + 2) + u4(2000) + strl("mm") + f4(10.0) + f8(100.0)
            + f8(5000.0) + f8(500.0) + f8(1.0) + u4(1000) + u4(1000) + u4(0) + u1(1)
            + b"".join(strl(f"POS{module}_{k}") for k in subs) + bytes(47))


def v4_tail(records: list[bytes] = ()) -> bytes:
    """What follows a V4 project's CPU name."""
    return CPU_REST + u4(len(records)) + u1(0) + b"".join(records) + PROJECT_INFO


# -- SMART V2 ----------------------------------------------------------------

def pwm_output(index: int, *, enabled: bool = True, time_base: int = 0) -> bytes:
    """One PWM output of the SMART PWM wizard (time base 0: µs, 1: ms)."""
    return (u1(1) + u4(int(enabled)) + u4(index) + strl(f"PWM{index}") + u4(time_base)
            + (u1(2) + u1(3) + u1(0x40) + bytes(8)) * 4)


def pid_loop(index: int, *, enabled: bool = False, gain: float = 1.0) -> bytes:
    """One loop of the SMART PID wizard."""
    return (u1(3) + (u1(2) + u1(3) + u1(0x40) + bytes(8)) * 14 + u1(1) + f4(gain) + f4(1.0)
            + f4(10.0) + f4(0.0) + bytes(1 + 8 + 8 + 4 + 1 + 8 + 12 + 4 + 1 + 12 + 8 + 1)
            + strl(f"PID{index}_CTRL") + bytes(4 + 1 + 4) + u4(int(enabled)) + u4(0)
            + u4(100 * index) + strl(""))


def hsc_counter(index: int, *, enabled: bool = False, mode: int = 0, steps: int = 0) -> bytes:
    """One counter of the SMART HSC wizard."""
    out = (u1(2) + u1(1) + u4(mode) + u1(1) + strl(f"HSC{index}_INIT") + bytes(2)
           + u4(0x01080201) + u4(0) + bytes(7) + u4(0x01080201) + u4(0) + bytes(9) + u4(0)
           + bytes(8) + u1(1))
    for name in ("EXTERN_RESET", "DIR_CHANGE", "COUNT_EQ"):
        out += u4(0) + strl(f"{name}{index}")
    out += u4(steps) + (u1(1) + u4(0) + strl("") + bytes(24)) * steps
    return out + u4(int(enabled)) + u4(index) + strl("", 1)


def motion_axis(index: int, *, profiles: int = 1) -> bytes:
    """One axis of the SMART motion wizard, with ``profiles`` one-step profiles."""
    out = u2(0x0104) + bytes(8) + u1(2) + u4(0) + strl("cm") + u4(5000) + f8(1.0)
    out += bytes(6 * 25 + 17) + u1(0) + u1(2) + f8(20.0) + f8(0.2) + f8(0.2)
    out += bytes(88) + u4(profiles)
    for _ in range(profiles):
        out += u1(2) + u4(1) + u1(2) + f8(5.0) + f8(100.0) + f8(0.0) + strl("P") + strl("")
        out += bytes(16)
    return out + u1(0) + u4(index) + bytes(72) + u4(0) + strl(f"Axis{index}") + bytes(8 + 308)


def smart_lists(axes: list[bytes] = (), pids: list[bytes] = (), hscs: list[bytes] = (),
                pwms: list[bytes] = ()) -> bytes:
    """What follows a SMART project's CPU name: its name, then the four lists."""
    out = CPU_REST + u1(0) + strl("Project1") + bytes(28)
    out += u1(3) + bytes(8) + u4(len(axes)) + b"".join(axes)
    out += u1(1) + u4(len(pids)) + b"".join(pids)
    out += strl("PID_EXE") + u2(2) * 3 + u1(0) + u4(0x22) + u1(8) + bytes(6 + 24)
    out += u1(2) + u4(4) + u4(len(hscs)) + b"".join(hscs)
    out += u1(1) + u4(len(pwms)) + b"".join(pwms)
    return out + bytes(16)


def wizard_tail(smart: bool) -> bytes:
    """No wizard configured: what the writer puts after the CPU name (for V4
    sixteen zero bytes: the CPU section's rest, no record, the start of the
    project's name section)."""
    return smart_lists() if smart else CPU_REST + u4(0) + u1(0) + bytes(5)
