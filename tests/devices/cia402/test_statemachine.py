"""The CiA 402 power state machine against the HCFA tables (§7.2–§7.4, §4.7)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from plcrt.devices.cia402.statemachine import (
    AUTOMATIC_TRANSITIONS, FAULT_CODES, HOLDS, IDLE_STATUSWORD, PERSONALITIES,
    STATUSWORD, TRANSITION_ROWS, TRANSITIONS, Cia402Error, Command, Drive402, State,
    decode_controlword, personality, quick_stop_plan, state_of_statusword,
)
from plcrt.errors import PlcError

S = State


def reach(state: State, model: str = "hcfa-am0520b", mode: int | None = None,
          qs_option: int = 2, dec: int = 1000) -> Drive402:
    """A drive brought to *state* by the manual's own steps."""
    d = Drive402(model, mode=mode, power_on=state is not S.NOT_READY_TO_SWITCH_ON)
    d.quick_stop_option, d.dec_6084, d.dec_6085 = qs_option, dec, dec
    path = {S.NOT_READY_TO_SWITCH_ON: [], S.SWITCH_ON_DISABLED: [],
            S.READY_TO_SWITCH_ON: [6], S.SWITCHED_ON: [6, 7],
            S.OPERATION_ENABLED: [6, 7, 0xF], S.QUICK_STOP_ACTIVE: [6, 7, 0xF, 2],
            S.FAULT_REACTION_ACTIVE: [], S.FAULT: []}[state]
    for cw in path:
        d.apply_controlword(cw, 0.0)
    if state is S.OPERATION_ENABLED and d.state is S.SWITCHED_ON:
        d.cycle(0.0)
    if state in (S.FAULT_REACTION_ACTIVE, S.FAULT):
        d.raise_fault(62, 62, "test", 0.0)
        if state is S.FAULT:
            d.cycle(0.0)
    assert d.state is state
    return d


# ---------------------------------------------------------------- the tables

#: HCFA §7.2 transition table, typed from the manual: (n, from, to, 6040h, 6041h after).
HCFA_7_2 = [
    (2, S.SWITCH_ON_DISABLED, S.READY_TO_SWITCH_ON, 0x0006, 0x0231),
    (3, S.READY_TO_SWITCH_ON, S.SWITCHED_ON, 0x0007, 0x0233),
    (4, S.SWITCHED_ON, S.OPERATION_ENABLED, 0x000F, 0x0237),
    (5, S.OPERATION_ENABLED, S.SWITCHED_ON, 0x0007, 0x0233),
    (6, S.SWITCHED_ON, S.READY_TO_SWITCH_ON, 0x0006, 0x0231),
    (7, S.READY_TO_SWITCH_ON, S.SWITCH_ON_DISABLED, 0x0000, 0x0250),
    (7, S.READY_TO_SWITCH_ON, S.SWITCH_ON_DISABLED, 0x0002, 0x0250),
    (8, S.OPERATION_ENABLED, S.READY_TO_SWITCH_ON, 0x0006, 0x0231),
    (9, S.OPERATION_ENABLED, S.SWITCH_ON_DISABLED, 0x0000, 0x0250),
    (10, S.SWITCHED_ON, S.SWITCH_ON_DISABLED, 0x0000, 0x0250),
    (10, S.SWITCHED_ON, S.SWITCH_ON_DISABLED, 0x0002, 0x0250),
    (11, S.OPERATION_ENABLED, S.QUICK_STOP_ACTIVE, 0x0002, 0x0217),
    (12, S.QUICK_STOP_ACTIVE, S.SWITCH_ON_DISABLED, 0x0000, 0x0250),
    (15, S.FAULT, S.SWITCH_ON_DISABLED, 0x0080, 0x0250),
    (16, S.QUICK_STOP_ACTIVE, S.OPERATION_ENABLED, 0x000F, 0x0237),
]


@pytest.mark.parametrize("n,src,dst,cw,sw", HCFA_7_2)
def test_every_controlword_transition_is_accepted_with_its_statusword(n, src, dst, cw, sw):
    """Each §7.2 row: from its state, its controlword makes that transition and
    6041h reads the table's value."""
    d = reach(src, qs_option=6 if n == 16 else 2)
    r = d.apply_controlword(cw, 1.0)
    assert r.transitions == (n,)
    assert d.state is dst and d.statusword == sw
    assert TRANSITION_ROWS[n].statusword == sw
    ev = d.log[-1]
    assert (ev.transition, ev.before, ev.after, ev.sw_after, ev.t) == (n, src, dst, sw, 1.0)
    assert "HCFA §7.2" in ev.section


def test_power_on_runs_transitions_0_and_1():
    """Power-on: 0 (NRTSO, 0x0000) then 1 (SOD, 0x0250), both automatic."""
    d = Drive402()
    assert [(e.transition, e.sw_after) for e in d.log] == [(0, 0x0000), (1, 0x0250)]
    assert Drive402(power_on=False).statusword == 0x0000


def test_error_during_initialisation_goes_straight_to_13():
    """§7.2 row 1: 'an error goes straight to 13'."""
    d = Drive402(power_on=False)
    r = d.power_on(0.0, fault=(4, 4, "EEPROM"))
    assert r.transitions == (0, 13) and d.state is S.FAULT_REACTION_ACTIVE


@pytest.mark.parametrize("state", [s for s in S if s is not S.NOT_READY_TO_SWITCH_ON])
def test_fault_makes_13_then_14_from_every_state(state):
    """13 from any state (0x021F), then 14 at the next cycle (0x0218)."""
    d = reach(state) if state not in (S.FAULT_REACTION_ACTIVE, S.FAULT) else reach(S.SWITCHED_ON)
    r = d.raise_fault(63, 63, "homing timeout", 1.0)
    assert r.transitions == (13,) and d.statusword == 0x021F
    assert r.actions[0].kind == "fault-reaction"
    assert d.error_code == 63 and d.error_register & 1
    assert d.cycle(2.0).transitions == (14,) and d.statusword == 0x0218


def test_automatic_transition_12_once_at_rest():
    """605Ah = 2 with 6085h > 0: QSA while ramping, 12 once the axis is at rest."""
    d = reach(S.QUICK_STOP_ACTIVE, qs_option=2, dec=5000)
    assert d.quick_stop is not None and d.quick_stop.ramp == "6085h"
    r = d.motion_stopped(3.0)
    assert r.transitions == (12,) and d.statusword == 0x0250


def test_enable_in_ready_is_two_steps_on_hcfa_and_one_on_kinco():
    """§7.4.1 '3**': 0x000F in RTSO gives SO on the HCFA, then 4 at the next
    cycle while held; the Kinco model (standard) goes through 3 and 4 at once."""
    h = reach(S.READY_TO_SWITCH_ON)
    assert h.apply_controlword(0xF, 0.0).transitions == (3,)
    assert h.cycle(0.001).transitions == (4,)
    k = reach(S.READY_TO_SWITCH_ON, "kinco-servo")
    assert k.apply_controlword(0xF, 0.0).transitions == (3, 4)


def test_transition_table_covers_every_number():
    """Transitions 0–16 all exist; controlword ones are in the table, the rest automatic."""
    assert set(TRANSITION_ROWS) == set(range(17))
    assert set(TRANSITIONS.values()) | AUTOMATIC_TRANSITIONS == set(range(17))
    for (state, _), n in TRANSITIONS.items():
        assert TRANSITION_ROWS[n].source is state


# ---------------------------------------------------------------- refusals

_WORDS = {Command.SHUTDOWN: 6, Command.SWITCH_ON: 7, Command.ENABLE_OPERATION: 0xF,
          Command.DISABLE_VOLTAGE: 0, Command.QUICK_STOP: 2, Command.FAULT_RESET: 0x80}
REFUSED = [(s, c) for s in S for c in _WORDS
           if (s, c) not in TRANSITIONS and (s, c) not in HOLDS]


@pytest.mark.parametrize("state,cmd", REFUSED, ids=lambda x: str(x).replace(" ", "_"))
def test_every_refused_command_is_explained(state, cmd):
    """A command that is no transition from the state changes nothing and
    says why, naming the manual section; a changed controlword is logged."""
    d = reach(state)
    before, n, held = d.statusword, len(d.log), d.controlword
    r = d.apply_controlword(_WORDS[cmd], 1.0)
    assert r.transitions in ((), (14,))
    if state is not S.FAULT_REACTION_ACTIVE:
        assert d.state is state and d.statusword == before
    assert "HCFA §" in r.explanation and r.explanation
    logged = [e.transition for e in d.log[n:] if e.transition is None]
    assert logged == ([None] if _WORDS[cmd] != held else [])


@pytest.mark.parametrize("state,cw,needed", [
    (S.SWITCH_ON_DISABLED, 0x000F, "first 0x0006 Shutdown (2), then 0x0007 Switch on (3), "
                                   "then 0x000F Enable operation (4)"),
    (S.SWITCH_ON_DISABLED, 0x0007, "first 0x0006 Shutdown (2)"),
    (S.QUICK_STOP_ACTIVE, 0x0006, "0x0000 Disable voltage (12)"),
    (S.QUICK_STOP_ACTIVE, 0x0007, "SWITCH ON DISABLED: 0x0006 Shutdown (2), then 0x0007"),
    (S.FAULT, 0x000F, "0x0080 Fault reset (15), then 0x0006 Shutdown (2)"),
    (S.FAULT_REACTION_ACTIVE, 0x0006, "(transition 14"),
    (S.NOT_READY_TO_SWITCH_ON, 0x0006, "(transition 1"),
    (S.OPERATION_ENABLED, 0x0080, "it acts only in FAULT"),
])
def test_refusals_name_the_needed_steps(state, cw, needed):
    """The explanation names the controlwords and transitions that lead there."""
    assert needed in reach(state).apply_controlword(cw, 0.0).explanation


@pytest.mark.parametrize("state,cmd", sorted(HOLDS, key=str))
def test_holding_commands_keep_the_state(state, cmd):
    """The command that belongs to the state keeps it, without a transition."""
    d = reach(state, qs_option=6)
    r = d.apply_controlword(_WORDS[cmd], 0.0)
    assert r.transitions == () and d.state is state and "holds" in r.explanation


def test_transition_16_refused_unless_605A_is_5_to_8():
    """605Ah = 2: Enable operation in QSA is refused and explained."""
    d = reach(S.QUICK_STOP_ACTIVE, qs_option=2, dec=1000)
    r = d.apply_controlword(0xF, 0.0)
    assert r.transitions == () and d.state is S.QUICK_STOP_ACTIVE
    assert "605Ah = 2" in r.explanation and "16" in r.explanation


# ---------------------------------------------------------------- controlword

@pytest.mark.parametrize("cw,prev,cmd", [
    (0x0006, 0, Command.SHUTDOWN), (0x000E, 0, Command.SHUTDOWN),
    (0x0007, 0, Command.SWITCH_ON), (0x000F, 0, Command.ENABLE_OPERATION),
    (0x001F, 0, Command.ENABLE_OPERATION), (0x010F, 0, Command.ENABLE_OPERATION),
    (0x0000, 0, Command.DISABLE_VOLTAGE), (0x000D, 0, Command.DISABLE_VOLTAGE),
    (0x0002, 0, Command.QUICK_STOP), (0x000B, 0, Command.QUICK_STOP),
    (0x0080, 0, Command.FAULT_RESET), (0x008F, 0x000F, Command.FAULT_RESET),
    (0x0080, 0x0080, Command.NONE), (0x0086, 0x0080, Command.NONE),
])
def test_controlword_decode(cw, prev, cmd):
    """§7.4.1 bit combinations; bit 7 acts on its rising edge and masks all else while held."""
    assert decode_controlword(cw, prev) is cmd


def test_controlword_out_of_range_is_an_error():
    with pytest.raises(PlcError, match="UINT16"):
        decode_controlword(0x10000)


def test_fault_reset_on_edge_not_level():
    """Holding 0x0080 does not reset a second fault; 0 then 0x0080 does."""
    d = reach(S.FAULT)
    assert d.apply_controlword(0x80, 1.0).transitions == (15,)
    d.raise_fault(62, 62, "again", 2.0)
    d.cycle(2.1)
    assert d.state is S.FAULT
    assert d.apply_controlword(0x80, 3.0).transitions == ()
    assert d.cycle(3.1).transitions == () and d.state is S.FAULT
    d.apply_controlword(0x00, 4.0)
    assert d.apply_controlword(0x80, 5.0).transitions == (15,)
    assert d.error_code == 0 and d.error_register == 0


def test_reset_edge_in_fault_reaction_is_lost():
    """An edge during FRA is ignored (§7.2: reset acts in FAULT); it must come again."""
    d = reach(S.FAULT_REACTION_ACTIVE)
    r = d.apply_controlword(0x80, 0.0)
    assert r.transitions == (14,) and d.state is S.FAULT
    assert d.apply_controlword(0x80, 0.1).transitions == ()


# ---------------------------------------------------------------- statuswords

#: HCFA §7.3 per-mode table, typed from the manual: (mode, state, 6041h).
HCFA_7_3 = [
    (1, S.SWITCH_ON_DISABLED, 0x0650), (1, S.READY_TO_SWITCH_ON, 0x0631),
    (1, S.SWITCHED_ON, 0x0633), (1, S.OPERATION_ENABLED, 0x8637), (1, S.FAULT, 0x0638),
    (3, S.SWITCH_ON_DISABLED, 0x0650), (3, S.READY_TO_SWITCH_ON, 0x0631),
    (3, S.SWITCHED_ON, 0x0633), (3, S.OPERATION_ENABLED, 0x0237), (3, S.FAULT, 0x0638),
    (6, S.SWITCH_ON_DISABLED, 0x0670), (6, S.READY_TO_SWITCH_ON, 0x0631),
    (6, S.SWITCHED_ON, 0x0633), (6, S.OPERATION_ENABLED, 0x8737), (6, S.FAULT, 0x0638),
    (8, S.READY_TO_SWITCH_ON, 0x0631), (8, S.SWITCHED_ON, 0x0633),
    (8, S.OPERATION_ENABLED, 0x1637),
]


@pytest.mark.parametrize("mode,state,sw", HCFA_7_3)
def test_per_mode_idle_statuswords(mode, state, sw):
    """§7.3: the idle 6041h of each mode and state."""
    assert IDLE_STATUSWORD[(mode, state)] == sw
    d = reach(state, mode=mode)
    assert d.statusword == sw and state_of_statusword(sw) is state


@pytest.mark.parametrize("state,sw", [
    (S.NOT_READY_TO_SWITCH_ON, 0x0000), (S.SWITCH_ON_DISABLED, 0x0250),
    (S.READY_TO_SWITCH_ON, 0x0231), (S.SWITCHED_ON, 0x0233), (S.OPERATION_ENABLED, 0x0237),
    (S.QUICK_STOP_ACTIVE, 0x0217), (S.FAULT_REACTION_ACTIVE, 0x021F), (S.FAULT, 0x0218)])
def test_statusword_per_state(state, sw):
    """§7.2 values with no mode shown; each decodes back to its state (§7.4.2)."""
    assert STATUSWORD[state] == sw and reach(state).statusword == sw
    assert state_of_statusword(sw) is state


def test_no_main_power_clears_bit_4():
    d = reach(S.SWITCH_ON_DISABLED)
    d.voltage_present = False
    assert d.statusword == 0x0240


def test_mode_bits_are_set_by_the_mode_layer_and_reset_by_a_transition():
    """Bits 8, 10–15 belong to the mode; a state change returns to the idle value."""
    d = reach(S.OPERATION_ENABLED, mode=1)
    d.set_mode_bits(0x1000)
    assert d.statusword == 0x1237
    d.apply_controlword(7, 0.0)
    assert d.statusword == 0x0633
    with pytest.raises(PlcError, match="bits 8 and 10"):
        d.set_mode_bits(0x0004)


def test_kinco_bit_15_means_homed_in_every_state_hcfa_does_not():
    """Kinco §2.6 bit 15 = reference found (stays set); HCFA's bit 15 is the mode's."""
    k = reach(S.SWITCHED_ON, "kinco-servo")
    k.homed = True
    assert k.statusword & 0x8000
    k.apply_controlword(0, 0.0)
    assert k.statusword == 0x8250
    h = reach(S.SWITCHED_ON)
    h.homed = True
    assert not h.statusword & 0x8000


# ---------------------------------------------------------------- quick stop

@pytest.mark.parametrize("option,dec,transitions,then", [
    (0, 1000, (11, 12), S.SWITCH_ON_DISABLED),
    (1, 1000, (11,), S.QUICK_STOP_ACTIVE), (2, 1000, (11,), S.QUICK_STOP_ACTIVE),
    (3, 1000, (11,), S.QUICK_STOP_ACTIVE), (4, 1000, (11,), S.QUICK_STOP_ACTIVE),
    (1, 0, (11, 12), S.SWITCH_ON_DISABLED), (2, 0, (11, 12), S.SWITCH_ON_DISABLED),
    (5, 1000, (11,), S.QUICK_STOP_ACTIVE), (6, 0, (11,), S.QUICK_STOP_ACTIVE),
    (7, 1000, (11,), S.QUICK_STOP_ACTIVE), (8, 1000, (11,), S.QUICK_STOP_ACTIVE),
])
def test_quick_stop_options(option, dec, transitions, then):
    """605Ah 0: disabled at once then SOD; 1–4 ramp then SOD; 5–8 stay in QSA;
    a ramp at 0 stops at once (and says so)."""
    d = reach(S.OPERATION_ENABLED, qs_option=option, dec=dec)
    r = d.apply_controlword(2, 1.0)
    assert r.transitions == transitions and d.state is then
    plan = r.actions[0].plan
    assert plan is not None and plan.option == option
    if dec == 0 and option:
        assert "stops at once" in plan.explanation
    if d.state is S.QUICK_STOP_ACTIVE:
        r2 = d.motion_stopped(2.0)
        if option <= 4:
            assert r2.transitions == (12,)
        else:
            assert r2.transitions == () and d.statusword == 0x0617


@pytest.mark.parametrize("option,hcfa,kinco", [(3, "6085h", "current limit"),
                                               (4, "6085h", "voltage limit"),
                                               (7, "6085h", "current limit"),
                                               (1, "6084h", "6084h"), (2, "6085h", "6085h")])
def test_limit_stops_ramp_on_6085h_on_the_stepper(option, hcfa, kinco):
    assert quick_stop_plan(option, 1, 1, True).ramp == hcfa
    assert quick_stop_plan(option, 1, 1, False).ramp == kinco


@pytest.mark.parametrize("option", [-1, 9, 65535])
def test_unknown_quick_stop_option_is_an_error(option):
    with pytest.raises(PlcError, match="0x06090030"):
        quick_stop_plan(option, 0, 0)


@pytest.mark.parametrize("option", [5, 6, 7, 8])
def test_transition_16_with_605A_5_to_8(option):
    d = reach(S.QUICK_STOP_ACTIVE, qs_option=option)
    d.motion_stopped(1.0)
    assert d.apply_controlword(0xF, 2.0).transitions == (16,)
    assert d.statusword == 0x0237 and d.quick_stop is None


# ---------------------------------------------------------------- faults

def test_fault_table_is_hcfa_4_7():
    """§4.7: codes, names and whether a reset clears them."""
    table = {4: False, 17: False, 8: False, 20640: False, 20704: False, 12828: False,
             12827: True, 10256: True, 62: True, 63: True, 35: True, 70: True, 71: True}
    for code, reset in table.items():
        assert FAULT_CODES[code].resettable is reset and FAULT_CODES[code].alarm == code


def test_power_cycle_only_fault_refuses_reset():
    """Alarm 4 (parameter storage, reset '否') is cleared by a power cycle only."""
    d = reach(S.SWITCHED_ON)
    d.raise_fault(4, 4, "EEPROM", 0.0)
    d.cycle(0.1)
    r = d.apply_controlword(0x80, 1.0)
    assert r.transitions == () and "power cycle" in r.explanation
    r = d.power_cycle(2.0)
    assert r.transitions == (0, 1) and d.error_code == 0 and d.state is S.SWITCH_ON_DISABLED


def test_reset_refused_while_the_cause_persists():
    d = reach(S.OPERATION_ENABLED)
    d.raise_fault(12827, 12827, "bus at 160 V", 0.0, cause_active=True)
    d.cycle(0.1)
    r = d.apply_controlword(0x80, 1.0)
    assert r.transitions == () and "bus at 160 V" in r.explanation
    d.clear_fault_cause()
    d.apply_controlword(0, 2.0)
    assert d.apply_controlword(0x80, 3.0).transitions == (15,)


@pytest.mark.parametrize("code,alarm,match", [(999, 999, "not in the HCFA"),
                                              (35, 36, "alarm 35"), (0x8611, 0x8611, "not alarm")])
def test_bad_fault_codes_are_errors(code, alarm, match):
    with pytest.raises(PlcError, match=match):
        reach(S.SWITCHED_ON).raise_fault(code, alarm, "x", 0.0)


def test_fault_while_in_fault_updates_the_code_without_a_transition():
    d = reach(S.FAULT)
    r = d.raise_fault(63, 63, "second", 1.0)
    assert r.transitions == () and d.error_code == 63 and d.state is S.FAULT


# ---------------------------------------------------------------- personalities

def test_personalities_cite_a_source_for_every_field():
    for p in PERSONALITIES.values():
        fields = set(p.__dataclass_fields__) - {"model", "sources"}
        assert fields == set(p.sources), p.model
    assert personality("kinco-servo").bit15 == "reference-found"
    assert personality("hcfa-am0520b").bit15 == "can-trigger"
    with pytest.raises(Cia402Error, match="unknown CiA 402 drive model 'x'"):
        personality("x")


# ---------------------------------------------------------------- properties

_CWS = st.sampled_from([0, 2, 6, 7, 0xF, 0x1F, 0x80, 0x86, 0x8F, 0x10F]) | \
    st.integers(0, 0xFFFF)
_OPS = st.one_of(
    st.tuples(st.just("cw"), _CWS), st.tuples(st.just("cycle"), st.none()),
    st.tuples(st.just("fault"), st.sampled_from([4, 35, 62, 12827])),
    st.tuples(st.just("stopped"), st.none()), st.tuples(st.just("clear"), st.none()),
    st.tuples(st.just("power"), st.none()))


@settings(max_examples=200, deadline=None)
@given(model=st.sampled_from(sorted(PERSONALITIES)), option=st.integers(0, 8),
       dec=st.sampled_from([0, 1000]), mode=st.sampled_from([None, 1, 3, 6, 8]),
       ops=st.lists(_OPS, max_size=40))
def test_any_sequence_keeps_statusword_and_log_consistent(model, option, dec, mode, ops):
    """Any sequence of controlwords, cycles and faults: 6041h always shows the
    state, and every logged transition is a legal row of the table."""
    d = Drive402(model, mode=mode)
    d.quick_stop_option, d.dec_6084, d.dec_6085 = option, dec, dec
    for i, (op, arg) in enumerate(ops):
        t = float(i)
        if op == "cw":
            d.apply_controlword(arg, t)
        elif op == "cycle":
            d.cycle(t)
        elif op == "fault":
            d.raise_fault(arg, arg, "property", t, cause_active=arg == 12827)
        elif op == "stopped":
            d.motion_stopped(t)
        elif op == "clear":
            d.clear_fault_cause()
        else:
            d.power_cycle(t)
        sw = d.statusword
        assert state_of_statusword(sw) is d.state
    for i, ev in enumerate(d.log, 1):
        assert ev.seq == i
        assert state_of_statusword(ev.sw_after) is ev.after or ev.after is S.NOT_READY_TO_SWITCH_ON
        if ev.transition is None:
            assert ev.before is ev.after
            continue
        if ev.command is not None:
            assert TRANSITIONS[(ev.before, ev.command)] == ev.transition
        else:
            assert ev.transition in AUTOMATIC_TRANSITIONS
        row = TRANSITION_ROWS[ev.transition]
        assert row.target is ev.after
        assert row.source in (None, ev.before) or ev.transition == 0
        if ev.transition == 16:
            assert option in (5, 6, 7, 8)


def test_605A_out_of_range_is_refused_when_set():
    """An option outside 0–8 never reaches a quick stop: setting it is an error."""
    d = reach(S.OPERATION_ENABLED)
    with pytest.raises(PlcError, match="0x06090030"):
        d.quick_stop_option = 9
    assert d.quick_stop_option == 2


def test_fault_during_quick_stop_drops_the_plan():
    d = reach(S.QUICK_STOP_ACTIVE, qs_option=2, dec=1000)
    d.raise_fault(62, 62, "x", 1.0)
    assert d.quick_stop is None
    assert d.motion_stopped(2.0).transitions == ()


def test_options_ending_in_sod_come_from_the_personality():
    assert quick_stop_plan(5, 1, 1, True, frozenset({5})).then is S.SWITCH_ON_DISABLED
    assert quick_stop_plan(2, 1, 1, True, frozenset()).then is S.QUICK_STOP_ACTIVE


@pytest.mark.parametrize("mode", [None, 1, 3, 6, 8])
def test_hcfa_enable_example_7_4_4(mode):
    """§7.4.4: write 0, 6, 7, 15 and test 0x250, 0x231, 0x233; the last check
    (sw & 0x237 == 0x1237) is a typo that no statusword can pass, while the
    strict state test (0x6F / 0x27) does."""
    d = Drive402(mode=mode)
    for cw, mask in ((0, 0x250), (6, 0x231), (7, 0x233)):
        d.apply_controlword(cw, 0.0)
        assert d.statusword & mask == mask
    d.apply_controlword(15, 0.0)
    assert d.statusword & 0x237 != 0x1237 and d.statusword & 0x6F == 0x27


def test_drive_command_leaves_the_held_controlword_alone():
    """The bus leaving OP takes the drive to SOD (9) on its own account; the
    master's held 0x000F then needs 0x0006 first and does not re-enable."""
    d = reach(S.OPERATION_ENABLED)
    r = d.command(Command.DISABLE_VOLTAGE, 1.0, "ESM left OP")
    assert r.transitions == (9,) and d.controlword == 0x000F
    assert d.log[-1].source == "ESM left OP"
    r = d.cycle(1.1)
    assert r.transitions == () and d.state is S.SWITCH_ON_DISABLED
    assert "first 0x0006 Shutdown (2)" in r.explanation


def test_event_log_text_names_transition_source_and_statuswords():
    d = reach(S.SWITCH_ON_DISABLED)
    d.apply_controlword(6, 2.5)
    assert str(d.log[-1]) == ("#3 t=2.5s transition 2 (6040h = 0x0006): SWITCH ON DISABLED -> "
                              "READY TO SWITCH ON, 6041h 0x0250 -> 0x0231 [HCFA §7.2]")
    assert d.log[-1].command is Command.SHUTDOWN


def test_refusal_in_fault_says_when_only_a_power_cycle_helps():
    d = reach(S.SWITCHED_ON)
    d.raise_fault(4, 4, "EEPROM", 0.0)
    d.cycle(0.1)
    r = d.apply_controlword(0x0F, 1.0)
    assert "only a power cycle clears it" in r.explanation and "§4.7" in r.explanation
    d = reach(S.SWITCHED_ON)
    d.raise_fault(12827, 12827, "bus at 160 V", 0.0, cause_active=True)
    d.cycle(0.1)
    assert "once its cause is gone (bus at 160 V)" in d.apply_controlword(6, 1.0).explanation
