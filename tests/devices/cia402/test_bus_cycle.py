"""The bus cycle's fast paths change nothing a master or a ladder program sees:
Drive.exchange (process data by object) and Drive.cycle (packed images) run the
same drive; the written-out CSP cycle gives, cycle by cycle, what the general
cycle gives; received writes reach every subscriber of the store; the values
of Drive.exchange are checked as before; a held controlword that changes
nothing adds nothing to the log."""

from __future__ import annotations

import random
from fractions import Fraction

import pytest
from hypothesis import given, settings, strategies as st

from plcrt.devices.cia402.drive import Drive
from plcrt.devices.cia402.drive_io import OWN_KEYS
from plcrt.devices.cia402.esm import EsmState
from plcrt.devices.cia402.modes import CyclicPosition, Mode, ProfilePosition, ProfileVelocity
from plcrt.devices.cia402.od import SdoAbort
from plcrt.devices.cia402.pdo import pack
from plcrt.devices.cia402.plant import DrivePlant
from plcrt.devices.cia402.statemachine import State
from plcrt.errors import PlcConfigError

OWN = (0x6041, 0x6061, 0x6062, 0x6064, 0x606C, 0x603F, 0x1001, 0x60F4, 0x60FD)
CW, TARGET = (0x6040, 0), (0x607A, 0)


def image(cw: int, target: int, probe: int = 0) -> bytes:
    """The default RxPDO 1600h: 6040h, 607Ah, 60B8h (HCFA §8.2)."""
    return (cw.to_bytes(2, "little") + target.to_bytes(4, "little", signed=True)
            + probe.to_bytes(2, "little"))


def in_op(**kw: object) -> Drive:
    d = Drive(**kw)                                  # type: ignore[arg-type]
    for s in (EsmState.PREOP, EsmState.SAFEOP, EsmState.OP):
        assert d.request_esm(s).accepted
    return d


def seen(d: Drive) -> tuple:
    """Everything a master, a ladder program or a test can see of a drive."""
    csp = d.engines[8]
    assert isinstance(csp, CyclicPosition)
    return (d.now, d.sm.state, d.statusword, d.mode_number, d.controlword,
            {key: d.store.get(*key) for key in ((i, 0) for i in OWN)},
            d.store.get(0x607A), d.store.get(0x60B8), d.axis.exact(d.now), d.axis.legs,
            csp.demand, csp.following_error, csp._fe_since, csp._last, csp.limit_stop,
            [str(e) for e in d.log])


def general_only(d: Drive) -> Drive:
    """The drive with its written-out CSP cycle switched off."""
    d._csp_fast = lambda t, rx, values: False      # type: ignore[method-assign]
    return d


def counting(d: Drive) -> list[bool]:
    """Record whether each cycle took the written-out CSP path."""
    taken: list[bool] = []
    fast = d._csp_fast

    def spy(t: int, rx: bytes | None, values: dict | None) -> bool:
        taken.append(fast(t, rx, values))
        return taken[-1]

    d._csp_fast = spy                               # type: ignore[method-assign]
    return taken


def enable_words(d: Drive) -> int:
    """The controlword a master sends next to reach OPERATION ENABLED."""
    return {State.FAULT: 0x00 if d.controlword & 0x80 else 0x80,
            State.SWITCH_ON_DISABLED: 0x06, State.READY_TO_SWITCH_ON: 0x07,
            State.QUICK_STOP_ACTIVE: 0x00}.get(d.sm.state, 0x0F)


def script(seed: int, steps: int) -> list[tuple]:
    """A master's CSP session: enable, follow a wandering target, now and
    then a jump the speed limit 6080h cuts short, a window 6065h small
    enough for a following error (fault 8611h, reset, enable again), a
    repeated or close bus time, a mode change to PP and back, the bus
    leaving OP, a touch-probe word 60B8h."""
    r = random.Random(seed)
    out: list[tuple] = []
    t, target = 0, 0
    for _ in range(steps):
        k = r.random()
        t += r.choice([1000] * 24 + [0, 1, 7, 500, 2000])
        if k < 0.01:
            out.append(("write", 0x6065, r.choice([5, 50, 100_000])))
        elif k < 0.015:
            out.append(("write", 0x6066, r.choice([0, 2])))
        elif k < 0.02:
            out.append(("write", 0x6060, r.choice([1, 8])))
        elif k < 0.025:
            out.append(("write", 0x6080, r.choice([40_000, 2_000_000])))
        elif k < 0.027:
            out.append(("esm", r.choice([EsmState.SAFEOP, EsmState.OP])))
        else:
            target += r.randint(-400, 400) if r.random() < 0.95 else r.randint(-30_000, 30_000)
            odd = r.random() < 0.03
            out.append(("cycle", t, target, r.choice([0x06, 0x07, 0x80, 0x00, 0x02, 0x1F])
                        if odd else None, r.randint(0, 3) if r.random() < 0.03 else 0))
    return out


def play(d: Drive, steps: list[tuple], by_object: bool) -> list[tuple]:
    trace = []
    for step in steps:
        kind = step[0]
        if kind == "write":
            d.write(step[1], 0, step[2])
            if step[1] == 0x6060 and step[2] != 8:
                d.write(0x6060, 0, 8)        # back to CSP at once: only the change is tested
        elif kind == "esm":
            d.request_esm(step[1])
            if d.esm.state is not EsmState.OP:
                d.request_esm(EsmState.OP)
        else:
            _, t, target, cw, probe = step
            cw = enable_words(d) if cw is None else cw
            t = max(t, d.now)
            if by_object:
                d.exchange(t, {CW: cw, TARGET: target, (0x60B8, 0): probe})
                trace.append(("tx", None))
            else:
                trace.append(("tx", d.cycle(t, image(cw, target, probe))))
        trace.append(seen(d))
    return trace


@pytest.mark.parametrize("by_object", [False, True], ids=["cycle", "exchange"])
@pytest.mark.parametrize("seed", range(6))
def test_the_written_out_csp_cycle_gives_what_the_general_cycle_gives(seed, by_object):
    steps = script(seed, 600)
    fast, slow = in_op(), general_only(in_op())
    taken = counting(fast)
    assert play(fast, steps, by_object) == play(slow, steps, by_object)
    assert sum(taken) > 20 and not all(taken)    # both paths ran


def play_sync(d: Drive, steps: list[tuple], held: bool) -> list[tuple]:
    """*steps* as a CANopen port's SYNCs run them (*held*: the drive's own
    objects held at the SYNC, then the cycle, with the store's lock held,
    as canopen_node.py does) or as two plain steps (advance, then the
    cycle by object); each SYNC's own objects and the drive after it."""
    trace = []
    for step in steps:
        if step[0] != "cycle":
            play(d, [step], True)
            continue
        _, t, target, cw, probe = step
        cw = enable_words(d) if cw is None else cw
        t, values = max(t, d.now), {CW: cw, TARGET: target, (0x60B8, 0): probe}
        with d.store.lock:
            if held:
                d.hold_locked(t)
                at_sync = d.deferred or tuple(d.store.get(*k) for k in OWN_KEYS)
                d.exchange_locked(t, values, True)
            else:
                d.advance(t)
                at_sync = tuple(d.store.get(*k) for k in OWN_KEYS)
                d.exchange(t, values)
        trace += [("sync", at_sync), seen(d)]
    return trace


@pytest.mark.parametrize("seed", range(4))
def test_a_sync_that_holds_the_objects_gives_what_two_plain_steps_give(seed):
    """The SYNC path of the CAN port (hold_locked, exchange_locked: the CSP
    line read at its end, the objects held for the TPDOs) gives the TPDOs'
    values and the drive that advance() and exchange() give, fault, reset,
    mode and window changes included."""
    steps = script(100 + seed, 600)
    held, plain = in_op(), in_op()
    general = []
    publish_deferred = held.publish_deferred

    def spy() -> None:
        general.append(True)
        publish_deferred()

    held.publish_deferred = spy                    # type: ignore[method-assign]
    assert play_sync(held, steps, True) == play_sync(plain, steps, False)
    syncs = sum(s[0] == "cycle" for s in steps)
    assert 0 < len(general) < syncs - 100          # the written-out hold ran, and the other


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(st.integers(-3000, 3000), st.sampled_from([0, 1, 999, 1000, 5000])),
                min_size=1, max_size=60),
       st.sampled_from([None, 3, 200, 10**6]), st.sampled_from([1000, 10**5, 10**7]))
def test_csp_set_points_give_the_same_drive_on_both_paths(moves, window, v_max):
    fast, slow = in_op(), general_only(in_op())
    for d in (fast, slow):
        if window is not None:
            d.write(0x6065, 0, window)
        d.write(0x6080, 0, v_max)
    t, target = 0, 0
    for delta, dt in [(0, 1000)] * 4 + moves:
        t, target = t + dt, target + delta
        for d in (fast, slow):
            d.cycle(t, image(enable_words(d), target))
        assert seen(fast) == seen(slow)


def test_exchange_and_cycle_run_the_same_drive_and_the_image_holds_its_objects():
    by_image, by_object = in_op(), in_op()
    for d in (by_image, by_object):
        d.write(0x6065, 0, 100_000)                # 6066h = 0: a fault at once beyond it
    t = 0
    for target in [0] * 4 + list(range(0, 40_000, 350)) + [39_000] * 5 + [-5_000_000] + [0] * 8:
        t += 1000
        for d in (by_image, by_object):
            cw = enable_words(d)
            if d is by_image:
                tx = d.cycle(t, image(cw, target))
            else:
                d.exchange(t, {CW: cw, TARGET: target, (0x60B8, 0): 0})
        assert seen(by_image) == seen(by_object)
        values = {(e.index, e.sub): int(by_object.store.get(e.index, e.sub))
                  for e in by_object.pdo.active_tx if e.index}
        assert tx == pack(by_object.pdo.active_tx, values)
    assert by_object.sm.state is State.OPERATION_ENABLED
    assert any("following error 60F4h" in str(e) for e in by_object.log)


def test_a_subscriber_of_the_store_sees_every_received_write_in_csp():
    d = in_op()
    t = 0
    for cw in (0x06, 0x07, 0x0F, 0x0F):
        t += 1000
        d.cycle(t, image(cw, 0))
    writes: list = []
    unsubscribe = d.store.on_write(writes.append)
    for k in range(1, 6):
        d.cycle(t + 1000 * k, image(0x0F, 100 * k))
    assert [(w.entry.index, w.value, w.old, w.source) for w in writes] == \
        [(0x607A, 100 * k, 100 * (k - 1), "pdo") for k in range(1, 6)]
    unsubscribe()
    d.exchange(t + 6000, {CW: 0x0F, TARGET: 700})
    assert len(writes) == 5 and d.store.get(0x607A) == 700


def test_exchange_checks_the_values_it_is_given():
    d = in_op()
    t = 0
    for cw in (0x06, 0x07, 0x0F, 0x0F):
        t += 1000
        d.exchange(t, {CW: cw, TARGET: 0})
    with pytest.raises(PlcConfigError, match="607Ah"):
        d.exchange(t + 1000, {CW: 0x0F, TARGET: 2**40})
    with pytest.raises(SdoAbort, match="7777h"):
        d.exchange(t + 2000, {CW: 0x0F, (0x7777, 0): 1})
    with pytest.raises(PlcConfigError):
        d.exchange(t + 3000, {CW: 0x0F, TARGET: True})
    d.exchange(t + 4000, {CW: 0x0F, TARGET: 250})
    assert d.store.get(0x607A) == 250 and d.sm.state is State.OPERATION_ENABLED


def test_exchange_in_pv_acts_on_60ffh_at_once():
    d = in_op()
    d.write(0x6083, 0, 1_000_000)
    d.write(0x6084, 0, 1_000_000)
    t = 0
    for cw in (0x06, 0x07, 0x0F, 0x0F):
        t += 1000
        d.exchange(t, {CW: cw, (0x6060, 0): 3})
    assert d.mode_number == 3 and d.sm.state is State.OPERATION_ENABLED
    d.exchange(t + 1000, {CW: 0x0F, (0x60FF, 0): 5000})
    d.exchange(t + 11_000, {CW: 0x0F, (0x60FF, 0): 5000})
    assert d.axis.velocity(d.now) == 5000          # ramped at 10^6 P/s² within 5 ms


def test_a_held_controlword_that_changes_nothing_adds_nothing_to_the_log():
    d = in_op()
    t = 1000
    d.cycle(t, image(0x0F, 0))                     # refused from SWITCH ON DISABLED, logged
    n = len(d.log)
    for k in range(2, 200):
        d.cycle(k * 1000, image(0x0F, 0))
    assert len(d.log) == n and d.sm.state is State.SWITCH_ON_DISABLED
    assert d.sm.cycle_acts() is False


def test_a_fault_reaction_still_ends_at_the_next_cycle():
    d = in_op()
    t = 0
    for cw in (0x06, 0x07, 0x0F, 0x0F):
        t += 1000
        d.cycle(t, image(cw, 0))
    d.fault(t, 0x8611, None, "test")
    assert d.sm.state is State.FAULT_REACTION_ACTIVE and d.sm.cycle_acts()
    d.cycle(t + 1000, image(0x0F, 0))
    assert d.sm.state is State.FAULT and not d.sm.cycle_acts()


def test_only_engines_with_a_parameter_method_take_parameters():
    class Custom(CyclicPosition):
        def parameter(self, t: int, index: int, sub: int) -> None:
            pass

    assert ProfileVelocity.takes_parameters and Custom.takes_parameters
    assert not (Mode.takes_parameters or CyclicPosition.takes_parameters
                or ProfilePosition.takes_parameters)


def test_a_csp_line_ends_at_an_exact_rest_position():
    d = in_op(plant=DrivePlant())
    t = 0
    for cw, target in ((0x06, 0), (0x07, 0), (0x0F, 0), (0x0F, 0), (0x0F, 123)):
        t += 1000
        d.cycle(t, image(cw, target))
    d.advance(t + 5000)
    x, v = d.axis.exact(d.now)
    assert isinstance(x, Fraction) and x == 123 and v == 0 and d.position == 123


def test_a_value_out_of_its_type_is_refused_after_the_values_before_it_are_written():
    d = in_op()
    d.write(0x6080, 0, 0xFFFF_FFFF)
    t = 0
    for cw in (0x06, 0x07, 0x0F, 0x0F):
        t += 1000
        d.cycle(t, image(cw, 0))
    with pytest.raises(PlcConfigError, match="606Ch"):
        d.cycle(t + 1, image(0x0F, -10**9))      # 4294 counts in 1 µs: 606Ch beyond I32
    # 6062h and 6064h come before 606Ch in the drive's outputs and are written
    assert d.store.get(0x6062) == -10**9 and d.store.get(0x6064) == d.axis.position(d.now)
    assert d.store.get(0x606C) == 0
