"""Property tests of the simulated EM253 through STL programs.

Random POS_GOTO_R moves, SPD_CTRL runs and POS_RUN envelopes (a random
profile table in a data block) run on both axes of a module in slot 0.
The axes are sampled at the end of every scan (``plc.axis``) and, by
splitting the module's time step, at random exact microseconds inside the
scans (the device is event driven, so splitting a step changes nothing).

Properties (EM253 user manual, chapter 3.2):

* final positions are exact: the counter moves by PosSet, or by the sum of
  the envelope's steps;
* the speed never exceeds SpdSet and changes no faster than note 3's ramp
  rate (SpdSet - SpdSs) / AccTime (DecTime when slowing down), except for
  the jump between 0 and the start/stop speed SpdSs;
* an Update (note 5) moves to the new PosSet exactly with the new ramps;
  Run = 0 ramps down to SpdSs and never passes PosSet;
* C_Pos, C_Spd and C_Step, written at each scan start, describe the axis
  at that microsecond;
* E_Stop (3.2.4-3.2.6) and the STF input (a scripted plant event) stop the
  pulses at once: speed 0 and the counter frozen at its value at that
  exact microsecond; a hard limit stops the axis exactly on it;
* SevOn = 1 (3.2.1) masks pulse and direction: the counter counts, the
  mechanics stay put;
* the module's terminals (2.2: STF, RPS, L+, L-, Z in; En, CLR, P, D out)
  equal the axis state at the end of every scan, moving or stopped;
* C_Step and C_Pos stay within the envelope (1..Step, 0..|PosSet| of that
  step), and no stop (Run = 0, E_Stop, InnerState) ends beyond the
  programmed end of a move;
* the two axes are independent;
* the results do not depend on the scan time;
* the cost of simulating does not grow with the pulse frequency.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from fractions import Fraction
from typing import Any, Callable, Optional

from hypothesis import HealthCheck, assume, event, example, given, settings
from hypothesis import strategies as st

import plcrt
from plcrt.devices import motion
from plcrt.devices.em253 import axis as axis_mod

F = Fraction
US = 1_000_000
SINGLE_ENDED_HZ = 200_000
DIFFERENTIAL_HZ = 500_000
LIMITS = {"limit_neg": -100_000_000, "limit_pos": 100_000_000}

#: examples per property; PLCRT_PROPERTY_EXAMPLES=500 for a deeper search
PROPS = settings(max_examples=int(os.environ.get("PLCRT_PROPERTY_EXAMPLES", "40")),
                 deadline=None,
                 suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


# ---------------------------------------------------------------------------
# programs
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Cmd:
    """One motion instruction on one axis and its parameters.

    kind: "goto" (POS_GOTO_R), "spd" (SPD_CTRL) or "run" (POS_RUN).
    ``table`` rows are (AccTime, DecTime, SpdSet, PosSet) for POS_RUN.
    """

    kind: str
    axis: int
    acc: int = 100
    dec: int = 100
    v_ss: int = 1000
    v_set: int = 10_000
    pos: int = 1000
    forward: bool = True
    table: tuple[tuple[int, int, int, int], ...] = ()

    # addresses: parameters at VB100 (axis 0) / VB200 (axis 1), bits in
    # M1 / M2 (.0 E_Stop, .1 Run, .2 Dir), the profile table at VB1000 / VB1400
    @property
    def base(self) -> int:
        return 100 + 100 * self.axis

    @property
    def run_bit(self) -> str:
        return f"M{1 + self.axis}.1"

    @property
    def estop_bit(self) -> str:
        return f"M{1 + self.axis}.0"

    @property
    def outputs(self) -> list[str]:
        """C_Status, C_Pos (not SPD_CTRL), C_Spd, C_Step (POS_RUN)."""
        b = self.base
        out = [f"VW{b + 22}", f"VD{b + 24}", f"VD{b + 28}", f"VB{b + 32}"]
        return {"goto": out[:3], "spd": [out[0], out[2]], "run": out}[self.kind]

    def call(self) -> str:
        b, m, a = self.base, 1 + self.axis, self.axis
        if self.kind == "goto":
            return (f"CALL POS_GOTO_R, 0, {a}, VW{b}, VW{b + 2}, VD{b + 4}, VD{b + 8}, "
                    f"VD{b + 12}, VD{b + 16}, VB{b + 20}, M{m}.0, M{m}.1, VW{b + 22}, "
                    f"VD{b + 24}, VD{b + 28}")
        if self.kind == "spd":
            return (f"CALL SPD_CTRL, 0, {a}, VW{b}, VW{b + 2}, VD{b + 4}, VD{b + 8}, "
                    f"VD{b + 16}, VB{b + 20}, M{m}.2, M{m}.0, M{m}.1, VW{b + 22}, VD{b + 28}")
        return (f"CALL POS_RUN, 0, {a}, 0, VD{b + 4}, &VB{1000 + 400 * a}, {len(self.table)}, "
                f"VD{b + 16}, VB{b + 20}, M{m}.0, M{m}.1, VW{b + 22}, VD{b + 24}, "
                f"VD{b + 28}, VB{b + 32}")

    def data(self) -> str:
        b = self.base
        lines = [f"VW{b} {self.acc}", f"VW{b + 2} {self.dec}", f"VD{b + 4} {self.v_ss}",
                 f"VD{b + 8} {self.v_set}", f"VD{b + 12} {self.pos}"]
        for i, (acc, dec, spd, pos) in enumerate(self.table):
            t = 1000 + 400 * self.axis + 12 * i
            lines += [f"VW{t} {acc}", f"VW{t + 2} {dec}", f"VD{t + 4} {spd}", f"VD{t + 8} {pos}"]
        return "\n".join(lines)

    def setup(self, plc: plcrt.Plc) -> None:
        if self.kind == "spd" and self.forward:
            plc[f"M{1 + self.axis}.2"] = 1

    # -- what the manual says about the move ------------------------------
    def distance(self) -> int:
        """Signed pulses of a positioning move."""
        if self.kind == "run":
            return sum(row[3] for row in self.table)
        return self.pos

    def top(self) -> int:
        return max(row[2] for row in self.table) if self.kind == "run" else self.v_set

    def rates(self) -> tuple[Fraction, Fraction]:
        """Largest ramp-up and ramp-down rates (Hz per µs), note 3."""
        rows = self.table or ((self.acc, self.dec, self.v_set, self.pos),)
        # an envelope step at SpdSs itself (the manual's own table ends with
        # one) has no note-3 rate; plcrt applies its times to the change
        # from the speed it enters with, at most the table's top speed
        top = max(row[2] for row in rows)
        change = [spd - self.v_ss if spd > self.v_ss else max(top - self.v_ss, 1)
                  for _, _, spd, _ in rows]
        up = max(F(c, row[0] * 1000) for c, row in zip(change, rows))
        down = max(F(c, row[1] * 1000) for c, row in zip(change, rows))
        return up, down

    def sign(self) -> int:
        if self.kind == "spd":
            return 1 if self.forward else -1
        return 1 if self.distance() > 0 else -1


def program(cmds: list[Cmd]) -> str:
    lines = ["ORGANIZATION_BLOCK MAIN:OB1", "BEGIN", "Network 1", "LD SM0.0",
             "CALL MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4, VW0"]
    for i, c in enumerate(cmds, 2):
        lines += [f"Network {i}", "LD SM0.0", c.call()]
    lines.append("END_ORGANIZATION_BLOCK")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------
# running and sampling
# ---------------------------------------------------------------------------
Sample = tuple[int, int, int, int]  #: (t µs, position, mechanical, speed Hz)


@dataclass
class Trace:
    plc: plcrt.Plc
    samples: dict[int, list[Sample]] = field(default_factory=lambda: {0: [], 1: []})
    outputs: dict[int, tuple[int, ...]] = field(default_factory=dict)  #: by scan start
    counts: dict[str, int] = field(default_factory=dict)

    def at(self, axis: int, t: int) -> Sample:
        return next(s for s in self.samples[axis] if s[0] == t)


def simulate(cmds: list[Cmd], script: list[tuple[int, str, int]], scan_ms: int,
             t_end: int, extra: tuple[int, ...] = (), differential: bool = False,
             events: Optional[dict[int, list[dict[str, Any]]]] = None,
             limits: Optional[dict[int, dict[str, int]]] = None,
             plant: Optional[str] = None) -> Trace:
    """Run the program of ``cmds`` until ``t_end`` µs.

    ``script``: (time µs, address, value) written before the scan that
    starts at that time (it must be a scan start).  ``extra``: exact times
    at which both axes are sampled inside the scans.  ``events``: scripted
    plant inputs per axis; ``limits`` replace the far-away default limits;
    ``plant`` (TOML text) replaces the whole plant.
    """
    axes = {}
    for a in (0, 1):
        ax: dict[str, Any] = dict(LIMITS)
        ax.update((limits or {}).get(a, {}))
        if events and a in events:
            ax["events"] = events[a]
        axes[str(a)] = ax
    plc = plcrt.load(program(cmds), plant=plant or {"module": {"0": {"axis": axes}}},
                     scan_ms=scan_ms,
                     data="\n".join(c.data() for c in cmds) + "\n")
    trace = Trace(plc)
    plc["M0.0"] = int(differential)
    for c in cmds:
        c.setup(plc)
    mod = plc.module(0)
    step = mod.step
    todo = sorted(set(extra))

    def record(t: int) -> None:
        for a in (0, 1):
            ax = mod.axes[a]
            trace.samples[a].append((t, ax.position(t), ax.mechanical(t), ax.speed(t)))

    def split_step(p: Any, t_from: int, t_to: int) -> None:
        t = t_from
        while todo and todo[0] <= t_from:
            todo.pop(0)
        while todo and todo[0] < t_to:
            ts = todo.pop(0)
            step(p, t, ts)
            record(ts)
            t = ts
        step(p, t, t_to)
        record(t_to)

    mod.step = split_step
    record(0)
    readers = [_reader(plc, o) for c in cmds for o in c.outputs]
    pending = sorted(script)
    while plc.now_us < t_end:
        now = plc.now_us
        while pending and pending[0][0] <= now:
            te, addr, value = pending.pop(0)
            assert te == now, f"command at {te} µs is not a scan start"
            plc[addr] = value
        plc.scan()
        check_terminals(plc, mod)
        trace.outputs[now] = tuple(r() for r in readers)
        for c in cmds:
            check_envelope_outputs(c, plc)
    assert all(d.severity == "warning" for d in plc.diagnostics), plc.diagnostics
    return trace


def check_terminals(plc: plcrt.Plc, mod: Any) -> None:
    """The module's input byte (in PI, read by the next scan) and output byte
    (in Q) equal the state of each axis at the end of the scan (manual 2.2),
    whether the axis moves or stands."""
    t = plc.now_us
    pi, q = plc.mem.areas["PI"], plc.mem.areas["Q"]
    for i, ax in enumerate(mod.axes):
        p, m = ax.plant, ax.mechanical(t)
        want_in = (int(ax.stf)
                   | (2 if p.rps is not None and p.rps[0] <= m <= p.rps[1] else 0)
                   | (4 if p.limit_pos is not None and m >= p.limit_pos else 0)
                   | (8 if p.limit_neg is not None and m <= p.limit_neg else 0)
                   | (16 if p.z_period and (m - p.z_offset) % p.z_period == 0 else 0))
        moving_now = plc.axis(mod.slot, i)["status"] == "moving" if i in mod.configured \
            else ax.moving
        want_out = (int(ax.masked)
                    | (4 if moving_now and not ax.masked else 0)
                    | (8 if ax.direction > 0 and not ax.masked else 0))
        assert pi[mod.di + i] == want_in, f"axis {i} inputs at {t} µs"
        assert q[mod.do + i] & ~2 == want_out, f"axis {i} outputs at {t} µs"


def check_envelope_outputs(cmd: Cmd, plc: plcrt.Plc) -> None:
    """C_Step within 0..Step and C_Pos within 0..|PosSet| of that step
    (POS_RUN, 3.2.6), C_Pos within 0..|PosSet| (POS_GOTO_R, 3.2.5), with
    the parameters as they stand in memory (an Update may change them)."""
    if cmd.kind == "spd":
        return
    b = cmd.base
    v = plc.mem.areas["V"]

    def dint(off: int) -> int:
        return int.from_bytes(v[off:off + 4], "big", signed=True)

    c_pos = dint(b + 24)
    if cmd.kind == "goto":
        assert 0 <= c_pos <= max(abs(cmd.pos), abs(dint(b + 12))), f"C_Pos {c_pos}"
        return
    step = v[b + 32]
    assert 0 <= step <= len(cmd.table), f"C_Step {step}"
    if step:
        pos_set = max(abs(cmd.table[step - 1][3]),
                      abs(dint(1000 + 400 * cmd.axis + 12 * (step - 1) + 8)))
        assert 0 <= c_pos <= pos_set, f"C_Pos {c_pos} in step {step}"
    else:
        assert c_pos == 0


def moving(trace: Trace, axis: int) -> bool:
    """The axis still moves at the end of the run (its speed may read 0
    while it moves slower than 1 Hz)."""
    return trace.plc.axis(0, axis)["status"] == "moving"


def _reader(plc: plcrt.Plc, address: str) -> Callable[[], int]:
    """A fast reader of VBn (unsigned), VWn / VDn (signed), as plc[address]."""
    v = plc.mem.areas["V"]
    off = int(address[2:])
    width = {"B": 1, "W": 2, "D": 4}[address[1]]
    signed = width > 1
    return lambda: int.from_bytes(v[off:off + width], "big", signed=signed)


def stops_abruptly(plc: plcrt.Plc) -> bool:
    """POS_RUN said its last step is too short to slow down to SpdSs (the
    pulses then end above SpdSs)."""
    return any("too short to decelerate" in d.message for d in plc.diagnostics)


def check_motion(samples: list[Sample], cmd: Cmd, t_start: int,
                 abrupt_stop: bool = False) -> None:
    """Speed limit, ramp rates, direction and travel between samples."""
    v_max = cmd.top()
    up, down = cmd.rates()
    sign = cmd.sign()
    prev: Optional[Sample] = None
    for s in samples:
        t, pos, _, v = s
        assert abs(v) <= v_max, f"speed {v} above SpdSet {v_max} at {t} µs"
        assert v == 0 or (v > 0) == (sign > 0), "speed against the direction"
        if prev is not None and t >= t_start:
            dt = t - prev[0]
            a0, a1 = abs(prev[3]), abs(v)
            if a0 and a1:
                assert a1 - a0 <= up * dt + 1, f"accelerates too fast at {t} µs ({prev}, {s})"
                assert a0 - a1 <= down * dt + 1, f"decelerates too fast at {t} µs ({prev}, {s})"
            elif a1:
                assert a1 <= cmd.v_ss + up * dt + 1, f"starts above SpdSs at {t} µs"
            elif a0 and not abrupt_stop:
                assert a0 <= cmd.v_ss + down * dt + 1, f"stops from above SpdSs at {t} µs"
            moved = (pos - prev[1]) * sign
            assert 0 <= moved <= v_max * F(dt, US) + 1, f"travel {moved} in {dt} µs at {t}"
        prev = s


# ---------------------------------------------------------------------------
# strategies
# ---------------------------------------------------------------------------
@st.composite
def speeds(draw: st.DrawFn, limit: int) -> tuple[int, int]:
    """(SpdSs, SpdSet) with SpdSs < SpdSet <= limit."""
    v_set = draw(st.one_of(st.integers(2, limit), st.sampled_from([limit, 5000, 80_000])
                           .filter(lambda v: v <= limit)))
    v_ss = draw(st.one_of(st.integers(0, v_set - 1), st.sampled_from([0, 5000])
                          .filter(lambda v: v < v_set)))
    return v_ss, v_set


ramp_ms = st.one_of(st.integers(1, 1500), st.sampled_from([1, 10, 1000]))


@st.composite
def goto_cmds(draw: st.DrawFn, axis: int, limit: int = SINGLE_ENDED_HZ) -> Cmd:
    v_ss, v_set = draw(speeds(limit))
    # at most about a second at SpdSet plus the ramps
    pos = draw(st.integers(1, max(1, v_set))) * draw(st.sampled_from([1, -1]))
    return Cmd("goto", axis, draw(ramp_ms), draw(ramp_ms), v_ss, v_set, pos)


@st.composite
def spd_cmds(draw: st.DrawFn, axis: int, limit: int = SINGLE_ENDED_HZ) -> Cmd:
    v_ss, v_set = draw(speeds(limit))
    return Cmd("spd", axis, draw(ramp_ms), draw(ramp_ms), v_ss, v_set,
               forward=draw(st.booleans()))


@st.composite
def run_cmds(draw: st.DrawFn, axis: int, limit: int = SINGLE_ENDED_HZ) -> Cmd:
    v_ss = draw(st.sampled_from([0, 1000, 5000]))
    n = draw(st.integers(1, 6))
    sign = draw(st.sampled_from([1, -1]))
    rows = []
    for _ in range(n):
        spd = draw(st.one_of(st.integers(max(v_ss, 1), limit), st.just(max(v_ss, 1))))
        pos = draw(st.integers(1, max(1, spd // (2 * n))))
        rows.append((draw(ramp_ms), draw(ramp_ms), spd, sign * pos))
    return Cmd("run", axis, v_ss=v_ss, table=tuple(rows))


def any_cmd(axis: int, limit: int = SINGLE_ENDED_HZ) -> st.SearchStrategy[Cmd]:
    return st.one_of(goto_cmds(axis, limit), spd_cmds(axis, limit), run_cmds(axis, limit))


def move_end_bound(cmd: Cmd) -> int:
    """A generous bound (µs) on the duration of a positioning move."""
    rows = cmd.table or ((cmd.acc, cmd.dec, cmd.v_set, cmd.pos),)
    t = 0
    for acc, dec, spd, pos in rows:
        # ramps at most AccTime + DecTime; the rest no slower than the
        # slowest speed a ramp can leave it at (the step's own time scale)
        t += (acc + dec) * 1000 + abs(pos) * US // max(1, min(spd, cmd.v_ss or spd)) + 1
    return t


# ---------------------------------------------------------------------------
# 1. positioning is exact, within SpdSet and the ramp rates
# ---------------------------------------------------------------------------
def _exact_move(cmd: Cmd, scan_ms: int, data: st.DataObject, differential: bool) -> None:
    start = scan_ms * 1000 * data.draw(st.integers(1, 5), label="start scan")
    t_end = start + min(move_end_bound(cmd), 4 * US) + 20_000
    extra = tuple(data.draw(st.lists(st.integers(start, t_end), max_size=40), label="extra"))
    tr = simulate([cmd], [(start, cmd.run_bit, 1)], scan_ms, t_end, extra, differential)
    samples = tr.samples[cmd.axis]
    check_motion(samples, cmd, start, stops_abruptly(tr.plc))
    last = samples[-1]
    if moving(tr, cmd.axis):
        event("still moving at the end")
        return  # a slow move still running at the (bounded) end: only the rates count
    assert last[1] == last[2] == cmd.distance(), "the counter must move by exactly PosSet"
    assert tr.plc.axis(0, cmd.axis)["status"] == "stopped"
    tr.plc.scan()
    status = tr.plc[cmd.outputs[0]]
    c_pos = tr.plc[cmd.outputs[1]]
    assert status == 8
    if cmd.kind == "goto":
        assert c_pos == abs(cmd.pos)
    else:
        assert c_pos == abs(cmd.table[-1][3]) and tr.plc[cmd.outputs[3]] == len(cmd.table)
    other = tr.samples[1 - cmd.axis]
    assert {s[1:] for s in other} == {(0, 0, 0)}, "the other axis must not move"
    check_reported_progress(tr, cmd, start)


def check_reported_progress(tr: Trace, cmd: Cmd, start: int) -> None:
    """C_Pos, C_Spd (and C_Step) written at each scan start describe the
    axis at that µs: C_Pos counts the pulses of the move (of the current
    envelope step), C_Spd is the signed speed, C_Step the step whose pulses
    are being sent."""
    state = {s[0]: s for s in tr.samples[cmd.axis]}
    bounds = [0]
    for row in cmd.table:
        bounds.append(bounds[-1] + abs(row[3]))
    for t, out in tr.outputs.items():
        if t <= start:
            continue
        _, pos, _, spd = state[t]
        moved = abs(pos)
        status = out[0]
        if status != 1:
            continue
        assert out[2] == spd, f"C_Spd {out[2]} != speed {spd} at {t} µs"
        if cmd.kind == "goto":
            assert out[1] == moved
        else:
            k = next((i for i, b in enumerate(bounds[1:], 1) if moved < b), len(cmd.table))
            assert (out[3], out[1]) == (k, moved - bounds[k - 1]), f"at {t} µs"


@PROPS
@given(axis=st.integers(0, 1), scan_ms=st.sampled_from([1, 2, 5, 10]), data=st.data())
def test_pos_goto_r_is_exact_within_speed_and_ramp(axis: int, scan_ms: int,
                                                   data: st.DataObject) -> None:
    differential = data.draw(st.booleans(), label="differential")
    cmd = data.draw(goto_cmds(axis, DIFFERENTIAL_HZ if differential else SINGLE_ENDED_HZ))
    _exact_move(cmd, scan_ms, data, differential)


@PROPS
@given(axis=st.integers(0, 1), scan_ms=st.sampled_from([1, 2, 5, 10]), data=st.data())
def test_pos_run_is_exact_within_speed_and_ramp(axis: int, scan_ms: int,
                                                data: st.DataObject) -> None:
    differential = data.draw(st.booleans(), label="differential")
    cmd = data.draw(run_cmds(axis, DIFFERENTIAL_HZ if differential else SINGLE_ENDED_HZ))
    _exact_move(cmd, scan_ms, data, differential)


@PROPS
@given(axis=st.integers(0, 1), scan_ms=st.sampled_from([1, 5, 10]), data=st.data())
def test_spd_ctrl_within_speed_and_ramp_and_update(axis: int, scan_ms: int,
                                                   data: st.DataObject) -> None:
    """Run, an Update to another SpdSet, then Run = 0: speeds stay within
    the largest SpdSet and the ramps of both parameter sets; the axis stops."""
    cmd = data.draw(spd_cmds(axis))
    new_set = data.draw(st.integers(cmd.v_ss + 1, SINGLE_ENDED_HZ), label="new SpdSet")
    scan = scan_ms * 1000
    t_upd = scan * data.draw(st.integers(2, 600 // scan_ms), label="update scan")
    t_off = t_upd + scan * data.draw(st.integers(1, 600 // scan_ms), label="off scan")
    b = cmd.base
    script = [(scan, cmd.run_bit, 1), (t_upd, f"VD{b + 8}", new_set), (t_upd, f"VB{b + 20}", 1),
              (t_off, cmd.run_bit, 0)]
    # note 3: after the Update the ramps follow the new SpdSet, so slowing
    # down from the old speed may take long (a lower SpdSet, a lower rate)
    new = replace(cmd, v_set=new_set)
    stop_us = (max(cmd.v_set, new_set) - cmd.v_ss) / new.rates()[1]
    t_end = t_off + int(min(stop_us, F(1_000_000))) + 2 * scan
    extra = tuple(data.draw(st.lists(st.integers(scan, t_end), max_size=40), label="extra"))
    tr = simulate([cmd], script, scan_ms, t_end, extra)
    both = replace(cmd, v_set=max(cmd.v_set, new_set))
    up = max(cmd.rates()[0], new.rates()[0])
    down = max(cmd.rates()[1], new.rates()[1])
    check_motion(tr.samples[axis], both, scan)
    # each parameter set's own rates (note 3), while it is in force
    for s0, s1 in zip(tr.samples[axis], tr.samples[axis][1:]):
        a0, a1 = abs(s0[3]), abs(s1[3])
        rates = cmd.rates() if s1[0] <= t_upd else new.rates() if s0[0] >= t_upd else (up, down)
        if a0 and a1:
            dt = s1[0] - s0[0]
            assert a1 - a0 <= rates[0] * dt + 1 and a0 - a1 <= rates[1] * dt + 1, (s0, s1)
    stopped = tr.plc.axis(0, axis)["status"] == "stopped"
    assert stopped or stop_us > 1_000_000, "Run = 0 must stop the axis after the ramp"
    tr.plc.scan()
    assert tr.plc[cmd.outputs[0]] == (8 if stopped else 1)


def check_rates(samples: list[Sample], phases: list[tuple[int, tuple[Fraction, Fraction]]]
                ) -> None:
    """Ramp rates between moving samples; ``phases``: (from µs, (up, down))
    in time order, the rates in force from that time on.  An interval that
    spans a change may use the larger of the rates involved."""
    for s0, s1 in zip(samples, samples[1:]):
        a0, a1 = abs(s0[3]), abs(s1[3])
        if not (a0 and a1):
            continue
        used = [r for i, (t, r) in enumerate(phases)
                if t < s1[0] and (i + 1 == len(phases) or phases[i + 1][0] > s0[0])]
        up, down = max(r[0] for r in used), max(r[1] for r in used)
        dt = s1[0] - s0[0]
        assert a1 - a0 <= up * dt + 1, f"accelerates too fast ({s0}, {s1})"
        assert a0 - a1 <= down * dt + 1, f"decelerates too fast ({s0}, {s1})"


@PROPS
@given(axis=st.integers(0, 1), scan_ms=st.sampled_from([1, 5, 10]), data=st.data())
def test_pos_goto_r_update_or_run_off_mid_move(axis: int, scan_ms: int,
                                               data: st.DataObject) -> None:
    """An Update with a new PosSet / SpdSet (same direction) ends exactly
    at the new PosSet unless that many pulses were already sent (then the
    axis stops beyond it, and says so); where the new ramps cannot end at
    PosSet from the current speed, the deceleration is made steeper (and
    says so) so that the count is still exact.  Run = 0 ramps down to SpdSs
    and never passes PosSet.  Each parameter set's ramps apply while it is
    in force."""
    cmd = data.draw(goto_cmds(axis))
    scan = scan_ms * 1000
    t_cmd = scan * data.draw(st.integers(2, 1_000 // scan_ms), label="command scan")
    sign = cmd.sign()
    b = cmd.base
    script = [(scan, cmd.run_bit, 1)]
    update = data.draw(st.booleans(), label="update (else Run = 0)")
    if update:
        new_pos = sign * data.draw(st.integers(1, 2 * abs(cmd.pos)), label="new PosSet")
        new_set = data.draw(st.integers(cmd.v_ss + 1, SINGLE_ENDED_HZ), label="new SpdSet")
        script += [(t_cmd, f"VD{b + 12}", new_pos), (t_cmd, f"VD{b + 8}", new_set),
                   (t_cmd, f"VB{b + 20}", 1)]
        new = replace(cmd, pos=new_pos, v_set=new_set)
    else:
        script.append((t_cmd, cmd.run_bit, 0))
        new = cmd
    t_end = t_cmd + min(move_end_bound(new) + move_end_bound(cmd), 3 * US) + 2 * scan
    extra = tuple(data.draw(st.lists(st.integers(scan, t_end), max_size=30), label="extra"))
    tr = simulate([cmd], script, scan_ms, t_end, extra)
    samples = tr.samples[axis]
    steep = any("programmed end" in d.message for d in tr.plc.diagnostics)
    passed = any("is already passed" in d.message for d in tr.plc.diagnostics)
    if not steep:
        check_motion(samples, replace(cmd, v_set=max(cmd.v_set, new.v_set)), scan)
        check_rates(samples, [(0, cmd.rates()), (t_cmd, new.rates())])
    if moving(tr, axis):
        event("still moving at the end")
        return  # still moving at the bounded end
    final = samples[-1][1] * sign
    if abs(tr.at(axis, t_cmd)[1]) >= abs(cmd.pos):
        # the move had sent all its pulses when the command came (it ends on
        # its last pulse, which may be exactly at the command's scan start):
        # nothing to update or stop
        assert final == abs(cmd.pos)
    elif update and not passed:
        assert final == abs(new.pos), "an updated PosSet must be reached exactly"
    elif update:
        assert final > abs(new.pos)
    else:
        assert final <= abs(cmd.pos), "Run = 0 must not run past PosSet"
    tr.plc.scan()
    assert tr.plc[cmd.outputs[0]] == 8 and tr.plc[cmd.outputs[1]] == final


@PROPS
@given(axis=st.integers(0, 1), scan_ms=st.sampled_from([1, 5, 10]), data=st.data())
def test_an_early_stop_never_ends_beyond_the_programmed_end(axis: int, scan_ms: int,
                                                            data: st.DataObject) -> None:
    """Run = 0, E_Stop or a write to InnerState at any scan of a POS_GOTO_R
    move or a POS_RUN envelope: the axis stops at or before the move's
    programmed end (PosSet, the envelope's total), C_Status reads 8, and
    C_Step / C_Pos name the step that was running and the pulses sent in
    it (3.2.5, 3.2.6)."""
    cmd = data.draw(st.one_of(goto_cmds(axis), run_cmds(axis)))
    scan = scan_ms * 1000
    bound = move_end_bound(cmd)
    t_cmd = scan * data.draw(st.integers(2, max(2, min(bound, 2 * US) // scan)),
                             label="stop scan")
    how = data.draw(st.sampled_from(["run0", "estop", "inner"]), label="stop")
    addr, value = {"run0": (cmd.run_bit, 0), "estop": (cmd.estop_bit, 1),
                   "inner": (f"VD{cmd.base + 16}", 12345)}[how]
    script = [(scan, cmd.run_bit, 1), (t_cmd, addr, value)]
    t_end = t_cmd + min(bound, 3 * US) + 2 * scan
    tr = simulate([cmd], script, scan_ms, t_end)
    if moving(tr, axis):
        event("still moving at the end")
        return
    total = abs(cmd.distance())
    final = tr.samples[axis][-1][1] * cmd.sign()
    assert 0 <= final <= total, f"stopped at {final}, beyond the programmed end {total}"
    tr.plc.scan()
    out = [tr.plc[o] for o in cmd.outputs]
    assert out[0] == 8
    if cmd.kind == "goto":
        assert out[1] == final
        return
    ends = [0]
    for row in cmd.table:
        ends.append(ends[-1] + abs(row[3]))
    k = next((i for i in range(1, len(ends)) if final < ends[i]), len(cmd.table))
    assert (out[3], out[1]) == (k, final - ends[k - 1]), (out, final, ends)


@PROPS
@given(axis=st.integers(0, 1), scan_ms=st.sampled_from([1, 5]), data=st.data())
def test_limit_switch_stops_on_the_first_pulse_that_reaches_it(axis: int, scan_ms: int,
                                                               data: st.DataObject) -> None:
    """A hard limit inside a move: the pulses stop at once when the pulse
    reaching the limit position is emitted, so the axis stands exactly on
    the limit, and until then the move is the same as without the limit."""
    cmd = data.draw(st.one_of(goto_cmds(axis, DIFFERENTIAL_HZ), run_cmds(axis, DIFFERENTIAL_HZ)))
    dist = cmd.distance()
    assume(abs(dist) >= 2)
    at = data.draw(st.integers(1, abs(dist) - 1), label="limit") * cmd.sign()
    scan = scan_ms * 1000
    t_end = scan + min(move_end_bound(cmd), 2 * US) + 20_000
    extra = tuple(data.draw(st.lists(st.integers(0, t_end), max_size=30), label="extra"))
    script = [(scan, cmd.run_bit, 1)]
    free = simulate([cmd], script, scan_ms, t_end, extra, differential=True)
    if moving(free, axis):
        event("still moving at the end")
        return  # a slow move still running at the (bounded) end
    key = "limit_pos" if at > 0 else "limit_neg"
    limited = simulate([cmd], script, scan_ms, t_end, extra, differential=True,
                       limits={axis: {key: at}})
    last = limited.samples[axis][-1]
    assert last[1:] == (at, at, 0), "the axis must stop exactly on the limit"
    t_hit = next(s[0] for s in limited.samples[axis] if s[1] == at)
    for s, twin in zip(limited.samples[axis], free.samples[axis]):
        if s[0] < t_hit and s[1] != at:
            assert s == twin
        else:
            assert s[1:] == (at, at, 0)
    assert any("hard limit" in d.message for d in limited.plc.diagnostics)
    limited.plc.scan()
    assert limited.plc[cmd.outputs[0]] == 8


# ---------------------------------------------------------------------------
# 2. E_Stop and STF stop the pulses at once
# ---------------------------------------------------------------------------
@PROPS
@given(axis=st.integers(0, 1), scan_ms=st.sampled_from([1, 5]), data=st.data())
def test_e_stop_freezes_the_counter_at_once(axis: int, scan_ms: int,
                                            data: st.DataObject) -> None:
    """E_Stop at a scan start: from that µs on, speed 0 and the counter as
    it was then.  E_Stop reset and a new rising edge of Run start a fresh
    move from there (a positioning move then ends exactly PosSet further)."""
    cmd = data.draw(any_cmd(axis))
    scan = scan_ms * 1000
    t_stop = scan * data.draw(st.integers(2, 600 // scan_ms), label="E_Stop scan")
    t_again = t_stop + scan * data.draw(st.integers(1, 50), label="restart scans")
    t_end = t_again + scan + min(move_end_bound(cmd), US) + 20_000
    extra = tuple(data.draw(st.lists(st.integers(scan, t_end), max_size=30), label="extra"))
    script = [(scan, cmd.run_bit, 1), (t_stop, cmd.estop_bit, 1),
              (t_again, cmd.estop_bit, 0), (t_again, cmd.run_bit, 0),
              (t_again + scan, cmd.run_bit, 1)]
    tr = simulate([cmd], script, scan_ms, t_end, extra)
    samples = tr.samples[axis]
    frozen = tr.at(axis, t_stop)          # the state when the block sees E_Stop
    held = [s for s in samples if t_stop < s[0] <= t_again + scan]
    assert held and all(s[1:] == (frozen[1], frozen[2], 0) for s in held), \
        "E_Stop must stop the pulses without deceleration"
    assert tr.outputs[t_stop][0] == 8
    abrupt = stops_abruptly(tr.plc)
    check_motion([s for s in samples if s[0] <= t_stop], cmd, scan, abrupt)
    check_motion([s for s in samples if s[0] >= t_again + scan], cmd, t_again + scan, abrupt)
    if cmd.kind != "spd" and not moving(tr, axis):
        assert samples[-1][1] == frozen[1] + cmd.distance()


@PROPS
@given(axis=st.integers(0, 1), scan_ms=st.sampled_from([1, 5, 10]), data=st.data())
@example(axis=0, scan_ms=10, data=None)   # the brief's event: STF at 1.234567 s
def test_stf_event_freezes_the_counter_at_that_microsecond(
        axis: int, scan_ms: int, data: Optional[st.DataObject]) -> None:
    extra: tuple[int, ...]
    if data is None:
        cmd = Cmd("spd", axis, 200, 200, 5000, 100_000)
        t_ev, extra = 1_234_567, (1_234_566, 1_234_568)
    else:
        cmd = data.draw(any_cmd(axis))
        t_ev = data.draw(st.integers(1, 1_500_000), label="STF time")
        extra = tuple(data.draw(st.lists(st.integers(1, t_ev + 300_000), max_size=30),
                                label="extra"))
    t_end = t_ev + 300_000
    extra = extra + (t_ev,)
    script = [(0, cmd.run_bit, 1)]
    ev = [{"at": t_ev / 1e6, "input": "STF", "value": True}]
    with_stf = simulate([cmd], script, scan_ms, t_end, extra, events={axis: ev})
    without = simulate([cmd], script, scan_ms, t_end, extra)
    # identical until the event; frozen from the event on, at the value the
    # counter had at that microsecond
    at_event = without.at(axis, t_ev)
    for s, twin in zip(with_stf.samples[axis], without.samples[axis]):
        assert s[0] == twin[0]
        if s[0] < t_ev:
            assert s == twin
        else:
            assert s[1:] == (at_event[1], at_event[2], 0), (s, at_event)
    if data is None:
        assert at_event[3] > 0, "the example must stop a moving axis"
    assert with_stf.plc["VW0"] == 4     # MOTION_EN3 Status: 4 = abnormal (STF)
    assert with_stf.plc.axis(0, axis)["stf"]
    assert with_stf.plc[cmd.outputs[0]] == 8    # stopped (by STF or at its end)


def test_stf_event_from_a_toml_plant_file() -> None:
    """The plant file's ``events = [{at = 1.234567, input = "STF", value =
    true}]`` stops a POS_GOTO_R move at that very µs: the counter keeps the
    value it had then, a µs earlier the axis was still sending pulses."""
    plant = """
[module.0.axis.0]
limit_neg = -2000000
limit_pos = 3000000
events = [{at = 1.234567, input = "STF", value = true}]
"""
    cmd = Cmd("goto", 0, 500, 500, 5000, 80_000, 1_000_000)
    t_ev = 1_234_567
    extra = (t_ev - 1, t_ev, t_ev + 1)
    tr = simulate([cmd], [(0, cmd.run_bit, 1)], 10, 2_000_000, extra, plant=plant)
    free = simulate([cmd], [(0, cmd.run_bit, 1)], 10, 2_000_000, extra)
    before, at, after = (tr.at(0, t) for t in extra)
    assert before == free.at(0, t_ev - 1) and before[3] == 80_000
    assert at[1:] == after[1:] == (free.at(0, t_ev)[1], free.at(0, t_ev)[1], 0)
    assert free.at(0, t_ev + 1)[1] > 0 and tr.samples[0][-1][1:] == at[1:]
    assert any("STF emergency stop at 1.234567 s" in d.message for d in tr.plc.diagnostics)


# ---------------------------------------------------------------------------
# 3. SevOn: the counter counts, the mechanics stay put
# ---------------------------------------------------------------------------
@PROPS
@given(axis=st.integers(0, 1), scan_ms=st.sampled_from([1, 5]), data=st.data())
def test_sev_on_masks_the_mechanics_not_the_counter(axis: int, scan_ms: int,
                                                    data: st.DataObject) -> None:
    """SevOn toggled at random scan starts while a move runs: the
    mechanical position changes exactly as the counter while SevOn = 0 and
    not at all while SevOn = 1."""
    cmd = data.draw(st.one_of(goto_cmds(axis), run_cmds(axis)))
    scan = scan_ms * 1000
    sev = f"M0.{1 + axis}"
    toggles = sorted(set(data.draw(st.lists(st.integers(0, 800 // scan_ms), max_size=6),
                                   label="toggles")))
    script = [(scan, cmd.run_bit, 1)]
    state = 0
    masked_from: list[tuple[int, int]] = [(0, 0)]
    for k in toggles:
        state ^= 1
        script.append((k * scan, sev, state))
    t_end = scan + min(move_end_bound(cmd), 2 * US) + 20_000
    extra = tuple(data.draw(st.lists(st.integers(0, t_end), max_size=30), label="extra"))
    tr = simulate([cmd], script, scan_ms, t_end, extra)
    # SevOn takes effect when MOTION_EN3 runs at the scan start
    state = 0
    for k in toggles:
        state ^= 1
        masked_from.append((k * scan, state))

    def masked_at(t: int) -> int:
        return [m for t0, m in masked_from if t0 <= t][-1]

    samples = tr.samples[axis]
    for s0, s1 in zip(samples, samples[1:]):
        d_pos, d_mech = s1[1] - s0[1], s1[2] - s0[2]
        # the mask is constant on (s0, s1] unless a scan start in between toggles it
        changes = {masked_at(t) for t, _ in masked_from if s0[0] < t <= s1[0]}
        m = masked_at(s1[0])
        if changes or masked_at(s0[0]) != m:
            continue
        if m:
            assert d_mech == 0, f"the mechanics moved while SevOn = 1 ({s0}, {s1})"
        else:
            assert d_mech == d_pos, f"the mechanics did not follow ({s0}, {s1})"


def test_sev_on_before_a_move_keeps_the_machine_still() -> None:
    """The documented decision: SevOn = 1 during a whole move; the counter
    reaches PosSet, the mechanical position stays at its start."""
    cmd = Cmd("goto", 1, 50, 50, 1000, 20_000, -15_000)
    tr = simulate([cmd], [(0, "M0.2", 1), (5000, cmd.run_bit, 1)], 5, 1_500_000,
                  extra=tuple(range(7000, 1_500_000, 9973)))
    samples = tr.samples[1]
    assert {s[2] for s in samples} == {0}
    assert samples[-1][1] == -15_000 and any(s[3] != 0 for s in samples)
    assert tr.plc["QB3"] & 0b1101 == 0b0001   # En set; no P, no D while masked


# ---------------------------------------------------------------------------
# 4. the axes are independent; 5. the scan time does not matter
# ---------------------------------------------------------------------------
@PROPS
@given(data=st.data())
def test_second_axis_is_unaffected_by_the_first(data: st.DataObject) -> None:
    cmd1 = data.draw(any_cmd(1), label="axis 1")
    cmd0 = data.draw(any_cmd(0), label="axis 0")
    scan_ms = data.draw(st.sampled_from([1, 5]), label="scan_ms")
    scan = scan_ms * 1000
    t1 = scan * data.draw(st.integers(0, 100), label="axis 1 start")
    t0 = scan * data.draw(st.integers(0, 100), label="axis 0 start")
    t_end = 1_200_000
    extra = tuple(data.draw(st.lists(st.integers(0, t_end), max_size=30), label="extra"))
    alone = simulate([cmd1], [(t1, cmd1.run_bit, 1)], scan_ms, t_end, extra)
    both = simulate([cmd0, cmd1], [(t1, cmd1.run_bit, 1), (t0, cmd0.run_bit, 1)], scan_ms,
                    t_end, extra)
    assert both.samples[1] == alone.samples[1]
    n = len(cmd1.outputs)
    assert {t: o[-n:] for t, o in both.outputs.items()} == alone.outputs
    assert any(o[0] == 1 for o in both.outputs.values()), "axis 0 must have run"


@PROPS
@given(data=st.data())
def test_results_do_not_depend_on_the_scan_time(data: st.DataObject) -> None:
    """Commands (Run, an Update of SpdSet, Run = 0 or E_Stop) at multiples
    of 5 ms: at every common time (the 5 ms scan boundaries and random exact
    times) both axes are in the same state with 1 ms and 5 ms scans, and the
    blocks report the same at common scan starts."""
    cmds = [data.draw(any_cmd(0), label="axis 0"), data.draw(any_cmd(1), label="axis 1")]
    script: list[tuple[int, str, int]] = []
    for c in cmds:
        on = 5000 * data.draw(st.integers(0, 60), label="start")
        script.append((on, c.run_bit, 1))
        if c.kind != "run" and data.draw(st.booleans(), label="update"):
            upd = on + 5000 * data.draw(st.integers(1, 60), label="update at")
            new_set = data.draw(st.integers(c.v_ss + 1, SINGLE_ENDED_HZ), label="new SpdSet")
            script += [(upd, f"VD{c.base + 8}", new_set), (upd, f"VB{c.base + 20}", 1)]
        if data.draw(st.booleans(), label="stop early"):
            off = on + 5000 * data.draw(st.integers(1, 120), label="Run = 0 or E_Stop")
            if data.draw(st.booleans(), label="E_Stop"):
                script.append((off, c.estop_bit, 1))
            else:
                script.append((off, c.run_bit, 0))
    t_end = 1_000_000
    extra = tuple(data.draw(st.lists(st.integers(0, t_end), max_size=30), label="extra"))
    fine = simulate(cmds, script, 1, t_end, extra)
    coarse = simulate(cmds, script, 5, t_end, extra)
    for a in (0, 1):
        common = {s[0] for s in coarse.samples[a]}
        fine_common = [s for s in fine.samples[a] if s[0] in common]
        assert fine_common == coarse.samples[a]
    assert {t: o for t, o in fine.outputs.items() if t in coarse.outputs} == coarse.outputs


# ---------------------------------------------------------------------------
# 6. the cost does not grow with the frequency
# ---------------------------------------------------------------------------
def _count_events(v_set: int, monkeypatch: Any) -> dict[str, int]:
    """Run 2 s of SPD_CTRL at ``v_set`` (differential output) and a
    POS_GOTO_R move on the other axis; count the kinematic work done."""
    counts = {"segs": 0, "first_time_at": 0, "arm": 0, "rebase": 0}

    def counting(name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        def wrapper(*args: Any, **kw: Any) -> Any:
            counts[name] += 1
            return fn(*args, **kw)
        return wrapper

    monkeypatch.setattr(motion.Seg, "__post_init__",
                        counting("segs", motion.Seg.__post_init__))
    monkeypatch.setattr(axis_mod, "first_time_at", counting("first_time_at",
                                                            axis_mod.first_time_at))
    monkeypatch.setattr(axis_mod.Axis, "_arm", counting("arm", axis_mod.Axis._arm))
    monkeypatch.setattr(axis_mod.Axis, "_rebase", counting("rebase", axis_mod.Axis._rebase))
    spd = Cmd("spd", 0, 300, 300, 1000, v_set)
    goto = Cmd("goto", 1, 300, 300, 1000, v_set, 2 * v_set // 3)
    tr = simulate([spd, goto], [(0, spd.run_bit, 1), (0, goto.run_bit, 1),
                                (1_500_000, spd.run_bit, 0)], 10, 2_000_000,
                  differential=True)
    assert tr.plc.axis(0, 1)["position"] == 2 * v_set // 3
    assert tr.plc.axis(0, 0)["status"] == "stopped"
    assert abs(tr.plc.axis(0, 0)["position"]) > v_set
    monkeypatch.undo()
    return counts


def test_cost_does_not_grow_with_the_frequency(monkeypatch: Any) -> None:
    """2 s of motion at 5 kHz and at 500 kHz do the same number of axis
    events (segments planned, crossing solves, re-arms, moves folded in),
    although the second emits 100 times as many pulses."""
    slow = _count_events(5_000, monkeypatch)
    fast = _count_events(500_000, monkeypatch)
    assert slow == fast
    assert 0 < fast["segs"] < 50


# ---------------------------------------------------------------------------
# the axis on its own
# ---------------------------------------------------------------------------
def test_axis_empty_replan_keeps_the_emitted_pulses() -> None:
    """Regression: re-planning a running move with an empty plan (keep the
    travel, nothing left to do) lost the pulses already sent."""
    ax = axis_mod.Axis(axis_mod.AxisPlant())
    segs, _ = motion.plan_distance(F(0), F(0), F(1000), F(1000), F(1000), F(500),
                                   F(1), F(1))
    ax.start(0, -1, segs)
    ax.advance(100_000)
    assert ax.position(100_000) == -100
    ax.start(100_000, -1, [], keep_travel=True)
    ax.advance(200_000)
    assert not ax.moving
    assert ax.position(200_000) == ax.mechanical(200_000) == -100


@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_axis_queries_at_any_time_of_the_move(data: st.DataObject) -> None:
    """position/speed/exact_state at a time do not depend on which times
    were asked before (the segment index may have to step back)."""
    v = data.draw(st.integers(1000, 100_000), label="v_max")
    length = data.draw(st.integers(10, 5000), label="length")
    r = F(data.draw(st.integers(1, 1000)), 1000)
    segs, _ = motion.plan_distance(F(0), F(0), F(0), F(v), F(0), F(length), r, r)
    end = segs[-1].t1_ceil
    assert end is not None
    times = data.draw(st.lists(st.integers(0, end + 10), min_size=2, max_size=20))
    fresh = {}
    for t in times:
        one = axis_mod.Axis(axis_mod.AxisPlant())
        one.start(0, 1, list(segs))
        fresh[t] = (one.position(t), one.speed(t), one.exact_state(t))
    shared = axis_mod.Axis(axis_mod.AxisPlant())
    shared.start(0, 1, list(segs))
    for t in times:
        assert (shared.position(t), shared.speed(t), shared.exact_state(t)) == fresh[t]
