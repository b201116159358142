"""The modes PP, PV and CSP of the simulated drive (HCFA §7.5, §7.6), in exact time."""

from __future__ import annotations

from hypothesis import given, settings, strategies as st

from plcrt.devices.cia402.drive import Drive
from plcrt.devices.cia402.statemachine import State


def enabled(mode: int, model: str = "hcfa-am0520b", **params: int) -> Drive:
    """A drive in OPERATION ENABLED in *mode*, with objects set by name 'x6081' etc."""
    d = Drive(model)
    d.write(0x6060, 0, mode)
    for key, value in params.items():
        index = int(key[1:5], 16)
        sub = int(key[6:], 16) if len(key) > 5 else 0
        d.write(index, sub, value)
    for cw in (0x06, 0x07, 0x0F):
        d.write(0x6040, 0, cw)
    if d.sm.state is State.SWITCHED_ON:          # HCFA §7.4.1 3**: 4 at the next cycle
        d.cycle(d.now)
    assert d.sm.state is State.OPERATION_ENABLED
    return d


PROFILE = dict(x6081=50_000, x6083=100_000, x6084=200_000)


def setpoint(d: Drive, target: int, cw: int = 0x1F) -> None:
    d.write(0x607A, 0, target)
    d.write(0x6040, 0, cw)
    d.write(0x6040, 0, cw & ~0x10)


# ---------------------------------------------------------------- PP

def test_pp_single_move_ends_exactly_on_target_at_the_planned_time():
    # 0.5 s up to 50 kP/s (12 500 P), 0.25 s down (6 250 P), 81 250 P at 50 kP/s = 1.625 s
    d = enabled(1, **PROFILE)
    assert d.statusword == 0x8637                    # HCFA §7.3 PP idle
    d.advance(1000)
    d.write(0x607A, 0, 100_000)
    d.write(0x6040, 0, 0x1F)
    assert d.statusword == 0x1237                    # §7.3: moving, bit 12 acknowledge
    d.write(0x6040, 0, 0x0F)
    assert d.statusword & 0x9400 == 0x8000           # bit 12 gone, bit 15 back, not reached
    d.advance(1000 + 2_375_000 - 1)
    assert d.position < 100_000 and not d.statusword & 0x0400
    d.advance(1000 + 2_375_000)
    assert d.position == 100_000 and d.store.get(0x6064) == 100_000
    assert d.statusword == 0x8637 and d.store.get(0x606C) == 0


def test_pp_set_of_set_points_starts_the_buffered_one_at_the_exact_end():
    d = enabled(1, **PROFILE)
    setpoint(d, 100_000)
    setpoint(d, 0)                                   # buffered (bit 5 = 0)
    assert d.statusword & 0x1000                     # buffer full: bit 12 stays
    setpoint(d, 50)                                  # refused: the buffer holds one
    assert any("buffer holds one" in e.text for e in d.log)
    d.advance(2_375_000)
    assert d.position == 100_000 and not d.statusword & 0x1000   # the buffered one is active
    d.advance(2_375_000 + 1000)
    assert d.axis.velocity(d.now) < 0                 # going back at once
    d.advance(20_000_000)
    assert d.position == 0 and d.statusword == 0x8637


def test_pp_relative_moves_add_to_the_previous_target():
    d = enabled(1, **PROFILE)
    setpoint(d, 1000, cw=0x5F)
    setpoint(d, -3000, cw=0x5F)                      # buffered, relative to target 1000
    d.advance(10_000_000)
    assert d.position == -2000
    setpoint(d, 500, cw=0x5F)
    d.advance(20_000_000)
    assert d.position == -1500


def test_pp_halt_stops_on_6084h_and_resumes():
    d = enabled(1, **PROFILE)
    setpoint(d, 100_000)
    d.advance(1_000_000)                             # cruising at 50 kP/s
    d.write(0x6040, 0, 0x10F)
    d.advance(1_250_000)                             # 50 000 / 200 000 = 0.25 s
    assert d.axis.velocity(d.now) == 0 and not d.moving
    assert d.statusword == 0x0737                    # HCFA §7.3 halt
    held = d.position
    d.advance(2_000_000)
    assert d.position == held
    d.write(0x6040, 0, 0x0F)
    d.advance(10_000_000)
    assert d.position == 100_000 and d.statusword == 0x8637


def test_pp_change_set_immediately_replaces_the_target_while_moving():
    d = enabled(1, **PROFILE)
    setpoint(d, 100_000)
    d.advance(1_000_000)
    setpoint(d, 40_000, cw=0x3F)                     # bit 5: at once
    d.advance(10_000_000)
    assert d.position == 40_000
    # a target behind the stopping distance: stop, come back, end exactly there
    setpoint(d, 100_000)
    d.advance(d.now + 1_000_000)
    setpoint(d, 60_000, cw=0x3F)
    d.advance(d.now + 10_000_000)
    assert d.position == 60_000 and d.statusword == 0x8637


def test_pp_zero_profile_parameter_refuses_the_set_point_with_bit_14():
    d = enabled(1, x6081=50_000, x6083=0, x6084=200_000)
    setpoint(d, 1000)
    assert d.statusword & 0x4000 and not d.statusword & 0x1000
    assert any("6083h = 0" in e.text for e in d.log)
    d.advance(1_000_000)
    assert d.position == 0


@settings(max_examples=40, deadline=None)
@given(target=st.integers(-200_000, 200_000), v=st.integers(1, 800_000),
       acc=st.integers(1, 5_000_000), dec=st.integers(1, 5_000_000),
       samples=st.lists(st.integers(0, 10**6), min_size=1, max_size=40))
def test_pp_position_never_passes_the_target_and_ends_on_it(target, v, acc, dec, samples):
    d = enabled(1, x6081=v, x6083=acc, x6084=dec)
    setpoint(d, target)
    end = d.axis.end_time() or 0
    last = 0
    for k in sorted(samples):                      # sampled times over the whole move
        d.advance(end * k // 10**6)
        pos = d.position
        assert min(0, target) <= pos <= max(0, target)
        assert (pos - last) * (1 if target >= 0 else -1) >= 0     # monotone
        last = pos
    d.advance(max(end, d.now))
    assert d.position == target and d.statusword & 0x0400


# ---------------------------------------------------------------- PV

def test_pv_ramps_on_6083h_and_6084h_and_reports_velocity_reached():
    d = enabled(3, x6083=100_000, x6084=50_000)
    assert d.statusword == 0x1637                     # at rest on target 0: bits 10 and 12
    d.write(0x60FF, 0, 20_000)                        # 0.2 s ramp
    assert not d.statusword & 0x0400                  # not yet reached; speed still 0 (bit 12)
    d.advance(1)
    assert not d.statusword & 0x1400
    d.advance(199_999)
    assert not d.statusword & 0x0400
    d.advance(200_000)
    assert d.store.get(0x606C) == 20_000 and d.statusword & 0x0400
    assert d.position == 2000                         # 20 000 * 0.2 / 2
    d.advance(1_200_000)
    assert d.position == 22_000
    d.write(0x60FF, 0, 0)                             # 0.4 s down on 6084h
    assert d.statusword & 0x1000 and not d.statusword & 0x0400   # ramping to 0: bit 12
    d.advance(1_600_000)
    assert d.position == 26_000 and d.statusword == 0x1637


def test_pv_reverses_through_zero_and_halt_stops():
    d = enabled(3, x6083=100_000, x6084=100_000)
    d.write(0x60FF, 0, 10_000)
    d.advance(1_000_000)                              # 0.1 s ramp (500) + 0.9 s (9000)
    assert d.position == 9500
    d.write(0x60FF, 0, -10_000)                       # 0.1 s down, 0.1 s up the other way
    d.advance(1_200_000)
    assert d.store.get(0x606C) == -10_000 and d.position == 9500 + 500 - 500
    d.write(0x6040, 0, 0x10F)
    d.advance(1_300_000)
    assert d.store.get(0x606C) == 0 and d.statusword & 0x0100
    d.write(0x6040, 0, 0x0F)
    d.advance(1_400_000)
    assert d.store.get(0x606C) == -10_000


# ---------------------------------------------------------------- CSP

def test_csp_follows_607ah_one_bus_cycle_later_without_following_error():
    d = enabled(8)
    assert d.statusword == 0x1637                     # HCFA §7.3 CSP idle
    for k in range(1, 60):              # at most 819 counts per ms: 6080h allows 833
        d.write(0x607A, 0, 7 * k * k)
        d.cycle(k * 1000)
        assert d.position == 7 * (k - 1) ** 2
        assert d.store.get(0x60F4) == 0
    assert d.statusword & 0x1000 and not d.statusword & 0x0400      # moving: 0x1237
    d.cycle(60 * 1000)
    d.cycle(61 * 1000)
    assert d.statusword == 0x1637


def test_csp_following_error_beyond_6065h_for_6066h_faults_with_8611h():
    d = enabled(8, x6065=100, x6066=2, x6080=10_000)  # 10 counts per 1 ms cycle at most
    d.cycle(0)
    d.write(0x607A, 0, 1000)
    d.cycle(1000)
    d.cycle(2000)                                     # 60F4h = 990: window exceeded since now
    assert d.store.get(0x60F4) == 990 and d.statusword & 0x2000
    d.cycle(3000)
    assert d.sm.state is State.OPERATION_ENABLED
    d.cycle(4000)                                     # 2 ms beyond the window
    assert d.sm.state is State.FAULT_REACTION_ACTIVE
    assert d.store.get(0x603F) == 0x8611 and d.store.get(0x1001) & 1
    d.cycle(5000)
    assert d.sm.state is State.FAULT and d.statusword == 0x0218
    held = d.position
    d.cycle(10_000)
    assert d.position == held                         # the axis is off
