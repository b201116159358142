"""The EtherCAT state machine: every transition and AL status code (HCFA §6.5,
digest §6.1/§6.2)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from plcrt.devices.cia402.esm import AL_CODES, Esm, EsmState, MappingProblem
from plcrt.errors import PlcError

E = EsmState
UP = [E.INIT, E.PREOP, E.SAFEOP, E.OP]


def esm_in(state: EsmState, problem: MappingProblem | None = None,
           outputs: str | None = None) -> Esm:
    esm = Esm(lambda: problem, (lambda: outputs))
    if state is E.BOOT:
        esm.request(E.BOOT)
    else:
        for s in UP[1:UP.index(state) + 1]:
            assert esm.request(s).accepted
    assert esm.state is state and not esm.error
    return esm


@pytest.mark.parametrize("src,dst", [
    (E.INIT, E.PREOP), (E.PREOP, E.SAFEOP), (E.SAFEOP, E.OP),          # up, one step
    (E.OP, E.SAFEOP), (E.OP, E.PREOP), (E.OP, E.INIT),                # down, may skip
    (E.SAFEOP, E.PREOP), (E.SAFEOP, E.INIT), (E.PREOP, E.INIT),
    (E.INIT, E.BOOT), (E.BOOT, E.INIT),
])
def test_every_legal_transition(src, dst):
    """HCFA §6.5 rules 1 and 2: up one at a time, down to any lower state."""
    esm = esm_in(src)
    r = esm.request(dst, t=1.0)
    assert r.accepted and esm.state is dst
    assert esm.al_status == int(dst) and esm.al_code == 0 and r.al_code == 0
    assert r.left_op is (src is E.OP)
    assert esm.log[-1].before is src and esm.log[-1].after is dst


@pytest.mark.parametrize("src,dst", [(E.INIT, E.SAFEOP), (E.INIT, E.OP), (E.PREOP, E.OP),
                                     (E.PREOP, E.BOOT), (E.SAFEOP, E.BOOT), (E.OP, E.BOOT),
                                     (E.BOOT, E.PREOP), (E.BOOT, E.OP)])
def test_skipping_upward_or_boot_is_refused_with_0x0011(src, dst):
    """A refused request keeps the state, sets the error flag and AL 0x0011."""
    esm = esm_in(src)
    r = esm.request(dst)
    assert not r.accepted and esm.state is src
    assert esm.al_status == int(src) | 0x10 and esm.al_code == 0x0011
    assert "0x0011" in r.explanation


def test_skip_explanation_names_the_steps():
    r = esm_in(E.INIT).request(E.OP)
    assert "INIT -> PRE-OP -> SAFE-OP -> OP" in r.explanation and "§6.5" in r.explanation


@pytest.mark.parametrize("value", [0, 5, 6, 7, 9, 10, 15])
def test_unknown_state_gives_0x0012(value):
    esm = esm_in(E.PREOP)
    r = esm.write_al_control(value)
    assert not r.accepted and esm.al_code == 0x0012 and esm.state is E.PREOP


def test_error_flag_ignores_requests_until_acknowledged():
    """While the error flag is set, AL Control without bit 4 is ignored; with
    bit 4 the error clears and the request is processed."""
    esm = esm_in(E.INIT)
    esm.request(E.OP)
    r = esm.request(E.PREOP)
    assert not r.accepted and esm.state is E.INIT and "acknowledge" in r.explanation
    r = esm.request(E.PREOP, ack=True)
    assert r.accepted and esm.state is E.PREOP and esm.al_status == 0x02 and esm.al_code == 0


def test_acknowledge_in_the_same_state_clears_the_error():
    esm = esm_in(E.PREOP)
    esm.request(E.OP)
    r = esm.write_al_control(0x12)
    assert r.accepted and esm.al_status == 0x02 and esm.al_code == 0


@pytest.mark.parametrize("side,code", [("outputs", 0x001D), ("inputs", 0x001E)])
def test_bad_mapping_stays_in_preop_with_alarm_35(side, code):
    """PRE-OP -> SAFE-OP with a bad assignment: PRE-OP, error flag, AL 0x001D
    (outputs) / 0x001E (inputs), and fault 603Fh = 35 for the drive."""
    esm = esm_in(E.PREOP, problem=MappingProblem(side, "1600h maps 6041h:00"))
    r = esm.request(E.SAFEOP)
    assert not r.accepted and esm.state is E.PREOP and esm.al_status == 0x12
    assert esm.al_code == code and r.al_code == code
    assert r.fault == (35, 35, "1600h maps 6041h:00")
    assert "1600h maps 6041h:00" in r.explanation


def test_validator_is_called_only_at_preop_to_safeop():
    calls: list[int] = []

    def validate() -> None:
        calls.append(1)

    esm = Esm(validate)
    esm.request(E.PREOP)
    esm.request(E.SAFEOP)
    esm.request(E.OP)
    esm.request(E.INIT)
    assert calls == [1]


def test_missing_outputs_refuse_op_with_0x0019():
    esm = esm_in(E.SAFEOP, outputs="no RxPDO received")
    r = esm.request(E.OP)
    assert not r.accepted and esm.state is E.SAFEOP and esm.al_code == 0x0019


def test_sm_watchdog_in_op_drops_to_safeop_with_alarm_17():
    esm = esm_in(E.OP)
    r = esm.sm_watchdog(2.0)
    assert esm.state is E.SAFEOP and esm.al_status == 0x14 and esm.al_code == 0x001B
    assert r.fault is not None and r.fault[:2] == (17, 17) and r.left_op


def test_sm_watchdog_outside_op_is_ignored():
    esm = esm_in(E.SAFEOP)
    r = esm.sm_watchdog()
    assert esm.state is E.SAFEOP and not esm.error and r.fault is None


@pytest.mark.parametrize("state,mailbox,inputs,outputs", [
    (E.INIT, False, False, False), (E.PREOP, True, False, False),
    (E.SAFEOP, True, True, False), (E.OP, True, True, True)])
def test_communication_per_state(state, mailbox, inputs, outputs):
    """HCFA §6.5 table: SDO from PRE-OP, TxPDO from SAFE-OP, RxPDO in OP."""
    esm = esm_in(state)
    assert (esm.mailbox, esm.inputs, esm.outputs) == (mailbox, inputs, outputs)


def test_al_code_table_is_the_digest_table():
    """Digest §6.2 (SOEM ethercatprint.c)."""
    assert set(AL_CODES) == {0x0000, 0x0001, 0x0011, 0x0012, 0x0016, 0x0017, 0x0018, 0x0019,
                             0x001A, 0x001B, 0x001D, 0x001E, 0x001F, 0x0024, 0x0025, 0x002C,
                             0x0030, 0x0034, 0x0035, 0x0036}
    assert AL_CODES[0x001D] == "invalid output configuration"


def test_al_control_out_of_range_is_an_error():
    with pytest.raises(PlcError, match="AL Control"):
        esm_in(E.INIT).write_al_control(0x10000)
    with pytest.raises(PlcError, match="bits 0–3"):
        esm_in(E.INIT).request(16)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 15), st.booleans()), max_size=30))
def test_any_request_sequence_keeps_the_rules(requests):
    """Every state change in the log is one step up or any step down (or the
    BOOT pair), and AL Status always equals state | error flag."""
    esm = Esm(lambda: None)
    for want, ack in requests:
        esm.request(want, ack=ack)
        assert esm.al_status == int(esm.state) | (0x10 if esm.error else 0)
        assert esm.error == (esm.al_code != 0)
    for ev in esm.log:
        if ev.before is ev.after:
            continue
        if E.BOOT in (ev.before, ev.after):
            assert {ev.before, ev.after} == {E.INIT, E.BOOT}
        else:
            assert UP.index(ev.after) <= UP.index(ev.before) + 1


@pytest.mark.parametrize("mode, cycle_ns, code", [
    (2, 199_000, 0x0036), (2, 10_000_001, 0x0036), (1, 100_000, 0x0035),
    (2, 200_000, 0), (2, 10_000_000, 0), (1, 250_000, 0), (0, 50_000, 0)])
def test_a_sync_cycle_outside_the_manual_is_refused_at_safeop(mode, cycle_ns, code):
    """HCFA §7.4.3: 200 µs to 10 ms.  SM-synchronous (1C32h:01 = 1) and DC
    SYNC0 (= 2) cycles outside it stay in PRE-OP with AL 0x0035 / 0x0036;
    free run (0) takes any cycle."""
    from plcrt.devices.cia402.drive import Drive

    d = Drive("hcfa-am0520b")
    d.request_esm(EsmState.PREOP)
    d.write(0x1C32, 1, mode)
    d.write(0x1C32, 2, cycle_ns)
    res = d.request_esm(EsmState.SAFEOP)
    assert res.accepted == (code == 0)
    assert d.esm.al_code == code
    assert d.esm.state is (EsmState.SAFEOP if code == 0 else EsmState.PREOP)
    if code:
        assert "HCFA §7.4.3" in res.explanation
