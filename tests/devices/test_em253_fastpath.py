"""The EM253's shortcuts change no result.

The module skips an axis until something is due on it (``Axis.wake``,
``Axis.next_change``: a watched crossing, the end of its move, a change of
one of its input bits, or a command), the readers compute inside the
current segment directly, and the library blocks report without running
their full rules while nothing is commanded (``__call__`` against
``call_exact``).  These tests pin each shortcut against the exact path:

* every example of ``programs/em253/``, with random commands (Run, E_Stop,
  direction, Update, SevOn, CLR, P_DorCCW) at random scan starts, gives
  the same memory image and the same axis states after every scan as a
  run in which every module step and every block call takes the exact
  path, at 1 ms and at 10 ms scans;
* an idle axis that the module skips starts at the exact scan start at
  which a command arrives;
* the time at which an axis's input bits can next change is never later
  than the change (checked position by position);
* the closed-form crossing time of a cruise equals the bisection's.
"""

from __future__ import annotations

import random
from fractions import Fraction
from pathlib import Path
from typing import Any, Callable, Iterator

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import plcrt
from plcrt.compiler import cache
from plcrt.devices import motion
from plcrt.devices.em253 import blocks as em_blocks
from plcrt.devices.em253.axis import NEVER, Axis, AxisPlant, velocity_plan
from plcrt.devices.em253.module import EM253Module
from plcrt.devices.em253.pos_run import PosRun

F = Fraction
EM253 = Path(__file__).resolve().parents[2] / "programs" / "em253"

#: the block classes whose __call__ has a shortcut in front of call_exact
BLOCKS = (em_blocks.MotionEn3, em_blocks.GetAbsPos, em_blocks.SetAbsPos, em_blocks.SpdCtrl,
          em_blocks.PosGotoR, em_blocks.Homing, PosRun)

#: example -> (plant, data block, bits set at power-up, bits toggled at
#: random scan starts, Update bytes set to 1 at random scan starts)
COMMON = ["M0.0", "M0.1", "M0.2", "M0.3", "M0.4"]   # P_DorCCW, SevOn0/1, Clr0/1
EXAMPLES: dict[str, tuple[str, str | None, list[str], list[str], list[str]]] = {
    "abs_pos.awl": ("plant.toml", None, ["M5.0", "M5.1"], ["M5.0", "M5.1", "M5.2"], ["VB524"]),
    "homing.awl": ("homing_plant.toml", None, ["M4.0", "M4.2"],
                   ["M4.0", "M4.1", "M4.2", "M4.3"], []),
    "pos_goto_r.awl": ("plant.toml", None, ["M2.0"], ["M2.0", "M2.1"], ["VB104"]),
    "pos_run.awl": ("plant.toml", "pos_run.db", ["M3.0"], ["M3.0", "M3.1"], ["VB304"]),
    "spd_ctrl.awl": ("plant.toml", None, ["M1.0", "M1.1", "M1.3", "M1.4"],
                     ["M1.0", "M1.1", "M1.2", "M1.3", "M1.4", "M1.5"], ["VB104", "VB204"]),
}


def _load(name: str, scan_ms: float) -> plcrt.Plc:
    plant, data, start, _, _ = EXAMPLES[name]
    plc = plcrt.load(EM253 / name, plant=EM253 / plant, scan_ms=scan_ms,
                     data=EM253 / data if data else None)
    for bit in start:
        plc[bit] = 1
    return plc


def load_exact(name: str, scan_ms: float, monkeypatch: pytest.MonkeyPatch) -> plcrt.Plc:
    """The example with every shortcut off: the generated code binds the
    blocks' ``call_exact`` (compiled anew, not from the program cache) and
    the module's axes are due at every step."""
    with monkeypatch.context() as m:
        m.setattr(cache.programs, "max_entries", 0)
        for cls in BLOCKS:
            m.setattr(cls, "__call__", cls.call_exact)
        plc = _load(name, scan_ms)
    for mod in plc.modules.values():
        for ax in mod.axes:
            ax.next_change = lambda t: 0   # type: ignore[method-assign]
    return plc


def _state(plc: plcrt.Plc) -> tuple[Any, ...]:
    return (plc.now_us, plc.mode, tuple(bytes(b) for b in plc.mem.areas.values()),
            tuple(a.to_dict() for a in plc.axes()))


def _commands(name: str, scans: int, scan_ms: float, seed: int) -> Iterator[list[tuple[str, int]]]:
    """Per scan, the writes before it: a toggled bit or an Update set, on
    average every 150 ms; Run bits more often than the others."""
    _, _, start, toggles, updates = EXAMPLES[name]
    rnd = random.Random(f"{name}-{scan_ms}-{seed}")
    state = {bit: 1 if bit in start else 0 for bit in toggles + COMMON}
    bits = toggles + toggles + COMMON
    for _ in range(scans):
        writes: list[tuple[str, int]] = []
        if rnd.random() < scan_ms / 150:
            if updates and rnd.random() < 0.2:
                writes.append((rnd.choice(updates), 1))
            else:
                bit = rnd.choice(bits)
                state[bit] ^= 1
                writes.append((bit, state[bit]))
        yield writes


def lockstep(name: str, fast: plcrt.Plc, exact: plcrt.Plc,
             commands: Iterator[list[tuple[str, int]]],
             state: Callable[[plcrt.Plc], Any]) -> None:
    """Give both runs the same writes before each scan and check that
    ``state`` of the two agrees after every scan."""
    for k, writes in enumerate(commands):
        for addr, value in writes:
            exact[addr] = value
            fast[addr] = value
        exact.scan()
        fast.scan()
        assert state(fast) == state(exact), f"{name}: differs after scan {k} ({writes})"


@pytest.mark.parametrize("scan_ms", [1, 10])
@pytest.mark.parametrize("name", sorted(EXAMPLES))
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_shortcuts_change_nothing_scan_by_scan(name: str, scan_ms: float, seed: int,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    """The fast run and the exact run of an example under the same random
    commands agree after every scan (memory image, axis states), and on
    their diagnostics at the end.  Seed 0 sends no command after the
    start, so the examples also run undisturbed."""
    exact = load_exact(name, scan_ms, monkeypatch)
    fast = _load(name, scan_ms)
    scans = round(6000 / scan_ms)
    commands = _commands(name, scans, scan_ms, seed) if seed else iter([[]] * scans)
    lockstep(name, fast, exact, commands, _state)
    assert [str(d) for d in fast.diagnostics] == [str(d) for d in exact.diagnostics]


def test_exact_run_takes_no_shortcut(monkeypatch: pytest.MonkeyPatch) -> None:
    """The reference of the test above is the exact path: its generated
    code calls the blocks' call_exact, and every module step goes through
    step_exact."""
    def bound(plc: plcrt.Plc) -> set[Any]:
        return {obj.__func__ for obj in plc._bindings.values()
                if isinstance(getattr(obj, "__self__", None), tuple(BLOCKS))}

    exact = load_exact("spd_ctrl.awl", 1, monkeypatch)
    fast = _load("spd_ctrl.awl", 1)
    assert bound(exact) == {em_blocks.MotionEn3.call_exact, em_blocks.SpdCtrl.call_exact,
                            em_blocks.GetAbsPos.call_exact}
    assert bound(fast) == {em_blocks.MotionEn3.__call__, em_blocks.SpdCtrl.__call__,
                           em_blocks.GetAbsPos.__call__}
    steps = 0
    step_exact = EM253Module.step_exact

    def counting(self: EM253Module, *a: Any) -> None:
        nonlocal steps
        steps += 1
        step_exact(self, *a)

    monkeypatch.setattr(EM253Module, "step_exact", counting)
    exact.scan(100)
    assert steps == 100
    assert exact.axis(0, 0).status == "moving"


def test_fast_run_skips_idle_and_steady_axes(monkeypatch: pytest.MonkeyPatch) -> None:
    """Without commands, the fast run leaves the module alone: an axis
    cruising at SpdSet with nothing ahead, or a stopped axis, is not due
    again (wake is its move's end, or never)."""
    plc = _load("spd_ctrl.awl", 1)
    plc.scan(7000)                       # both axes at SpdSet by 6 s
    exact_steps = 0
    step_exact = EM253Module.step_exact

    def counting(self: EM253Module, *a: Any) -> None:
        nonlocal exact_steps
        exact_steps += 1
        step_exact(self, *a)

    monkeypatch.setattr(EM253Module, "step_exact", counting)
    plc.scan(1000)
    assert exact_steps == 0
    mod = plc.module(0)
    # the limits at -2 000 000 are ahead of both axes running backwards:
    # their crossing is the next time an input bit changes
    assert all(plc.now_us < ax.wake < NEVER for ax in mod.axes)


@pytest.mark.parametrize("scan_ms", [1, 10])
def test_idle_skipped_axis_answers_a_command_at_its_scan_start(
        scan_ms: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """Axis 0 of spd_ctrl.awl stands still for 1 s (the module skips it:
    wake is never); Run set before the scan at 1 s starts it at exactly
    1 s: after t more, the counter is -floor(5000 t + 15000 t^2 / 2)
    (SpdSs 5 kHz, ramp 45 000 Hz in 3 s, direction M1.1 = 0: negative),
    as in the exact run."""
    fast = _load("spd_ctrl.awl", scan_ms)
    exact = load_exact("spd_ctrl.awl", scan_ms, monkeypatch)
    for plc in (fast, exact):
        for bit in ("M1.0", "M1.1", "M1.3", "M1.4"):
            plc[bit] = 0
        plc.run(1.0)
    ax = fast.module(0).axes[0]
    assert ax.wake == NEVER and not ax.segs
    for plc in (fast, exact):
        plc["M1.0"] = 1
    for k in range(1, 6):
        fast.scan()
        exact.scan()
        t = F(k * scan_ms, 1000)
        expect = -int(5000 * t + 15000 * t * t / 2)
        assert fast.axis(0, 0).position == exact.axis(0, 0).position == expect
        assert fast.axis(0, 1).position == 0
        assert _state(fast) == _state(exact)
    # the P bit (QB2.2) is on from the end of the first scan of the move
    assert fast["Q2.2"] == 1


# ---------------------------------------------------------------------------
# the input bits' next change, position by position
# ---------------------------------------------------------------------------
def _bits(ax: Axis, t: int) -> int:
    return EM253Module._bytes(ax, t, False)[0]


@settings(max_examples=60, deadline=None)
@given(lo=st.integers(-3000, 3000), width=st.integers(0, 400),
       lim_neg=st.one_of(st.none(), st.integers(-4000, -100)),
       lim_pos=st.one_of(st.none(), st.integers(100, 4000)),
       z_period=st.one_of(st.none(), st.integers(2, 900)), z_offset=st.integers(-500, 500),
       start=st.integers(-2000, 2000), direction=st.sampled_from([1, -1]),
       v_ss=st.integers(100, 3000), v_set=st.integers(3001, 20_000),
       ramp_ms=st.integers(1, 300), stop_ms=st.integers(50, 400))
def test_next_change_is_never_after_an_input_bit_changes(
        lo: int, width: int, lim_neg: int | None, lim_pos: int | None, z_period: int | None,
        z_offset: int, start: int, direction: int, v_ss: int, v_set: int, ramp_ms: int,
        stop_ms: int) -> None:
    """A move (ramp, cruise) on a plant with a reference switch, limits and
    Z marks: from each wake time to the next, every position the axis
    passes has the input bits of the position at the wake time, and the
    bits differ at the next wake where no event is due there."""
    plant = AxisPlant(start=start, rps=(lo, lo + width), limit_neg=lim_neg, limit_pos=lim_pos,
                      z_period=z_period, z_offset=z_offset)
    ax = Axis(plant)
    rate = F(v_set - v_ss, ramp_ms * 1000)
    ax.start(0, direction, velocity_plan(0, F(0), F(0), F(v_ss), F(v_set), rate, rate))
    horizon = stop_ms * 1000
    t = 0
    while t < horizon:
        wake = ax.next_change(t)
        assert wake > t
        bits = _bits(ax, t)
        last = min(wake, horizon + 1) - 1
        m0, m1 = ax.mechanical(t), ax.mechanical(last)
        step = 1 if m1 >= m0 else -1
        for m in range(m0, m1 + step, step):
            # _bytes reads only the mechanical position: a frozen axis at m
            ax.masked, ax.frozen = True, m
            assert _bits(ax, t) == bits, (t, wake, m)
            ax.masked = False
        if wake > horizon:
            break
        assert _bits(ax, wake) != bits   # no event on this axis: a bit changed
        t = wake


@settings(max_examples=200, deadline=None)
@given(t0=st.integers(0, 10**7), x0=st.integers(0, 10**6), v=st.integers(1, 500_000),
       length=st.one_of(st.none(), st.integers(1, 10**6)), ahead=st.integers(0, 10**6),
       lo_off=st.integers(0, 10**6))
def test_cruise_crossing_in_closed_form_equals_the_bisection(
        t0: int, x0: int, v: int, length: int | None, ahead: int, lo_off: int) -> None:
    """first_time_at solves a cruise with one division; the bisection it
    replaces (kept for ramps) gives the same µs."""
    seg = motion.cruise(F(t0), F(x0), F(v), F(length) if length is not None else None)
    tgt = x0 + ahead
    lo = t0 + lo_off
    got = motion.first_time_at(seg, tgt, lo)
    # the bisection on the same segment, with the closed form bypassed
    end = seg.t1_ceil
    if end is not None and (end < lo or seg.x1.numerator // seg.x1.denominator < tgt):
        assert got is None
        return

    def reached(t: int) -> bool:
        return (end is not None and t >= end) or seg.pulses(t) >= tgt

    hi = end if end is not None else lo + (tgt - x0 + 2) * 1_000_000 // v + 2
    if reached(lo):
        assert got == lo
        return
    a, b = lo, hi
    while b - a > 1:
        mid = (a + b) // 2
        if reached(mid):
            b = mid
        else:
            a = mid
    assert got == b
