"""The pulse-output wizard blocks (plcrt.devices.ptowizard; System Manual,
"Open-loop motion control"): PTOx_CTRL/RUN/MAN/LDPOS/ADV and PWMx_RUN over
the PLS model, configured by the plant's [pto.N] / [pwm.N].

Times are exact µs: with accel_ms = decel_ms = 0 a motion is constant-speed
trains whose ends a hand computation gives; with ramps the pulse counts are
exact and the ramp times are the documented closed forms
(docs/pto-wizard.md).  Scans are 10 ms; a block called in the scan at t0
acts at t0.
"""

from __future__ import annotations

import pytest

import plcrt
from plcrt.blocks.interface import interfaces
from plcrt.devices.plant import load_plant
from plcrt.devices.ptowizard import blocks as wz
from plcrt.devices.ptowizard.config import PtoConfig
from plcrt.devices.ptowizard.plan import cycle_us, ramp, ramp_pulses

CALLS = {
    "CTRL": "CALL PTO0_CTRL, M0.0, M0.1, M2.0, VB0, VD4",
    "RUN": "CALL PTO0_RUN, M0.2, VB1, M0.3, M2.1, VB2, VB3, VB8, VD10",
    "MAN": "CALL PTO0_MAN, M0.4, VD20, VB14, VD24",
    "LDPOS": "CALL PTO0_LDPOS, M0.5, VD30, M2.2, VB15, VD34",
    "ADV": "CALL PTO0_ADV, M0.6, M2.3, VB16, VD40",
    "PWM": "CALL PWM1_RUN, M1.0, VW50, VW52, VB54",
}


def program(*kinds: str, sbrs: str = "") -> str:
    nets = ["LD SM0.1\nATCH INT_0, 19\nENI"] + [f"LD SM0.0\n{CALLS[k]}" for k in kinds]
    out = ["ORGANIZATION_BLOCK MAIN:OB1", "BEGIN"]
    for i, net in enumerate(nets, 1):
        out += [f"Network {i}", *net.splitlines()]
    out += ["END_ORGANIZATION_BLOCK", "INTERRUPT_BLOCK INT_0:INT0", "BEGIN", "Network 1",
            "LD SM0.0", "INCW VW60", "END_INTERRUPT_BLOCK"]
    return "\n".join(out) + "\n" + sbrs


def plant(accel: int = 0, decel: int = 0, hsc: bool = True, ss: int = 200,
          mx: int = 20000, extra: str = "") -> str:
    return (f"[pto.0]\nmax_speed = {mx}\nss_speed = {ss}\naccel_ms = {accel}\n"
            f"decel_ms = {decel}\nhsc = {'true' if hsc else 'false'}\n"
            "[[pto.0.profile]]\nmode = \"relative\"\n"
            "steps = [ { speed = 5000, pulses = 1000 }, { speed = 1000, pulses = 500 } ]\n"
            "[[pto.0.profile]]\nmode = \"continuous\"\nspeed = 1000\nstop_pulses = 300\n"
            "[[pto.0.profile]]\nmode = \"continuous\"\nspeed = 2000\n" + extra)


def load(*kinds: str, **kw) -> plcrt.Plc:
    text = kw.pop("plant_text", None) or plant(**kw)
    return plcrt.load(program("CTRL", *kinds), plant=load_plant(text))


def pulse(plc: plcrt.Plc, bit: str, scans: int = 1) -> int:
    """Set *bit* for one scan; returns the time that scan ran at (µs)."""
    t = plc.now_us
    plc[bit] = 1
    plc.scan(scans)
    plc[bit] = 0
    return t


def sent(plc: plcrt.Plc) -> int:
    return plc.pulse[0].pulses_until(plc.now_us)


# -- interfaces ----------------------------------------------------------------
MANUAL_INTERFACES = {
    "CTRL": [("IN", "BOOL"), ("IN", "BOOL"), ("OUT", "BOOL"), ("OUT", "BYTE"), ("OUT", "DINT")],
    "RUN": [("IN", "BOOL"), ("IN", "BYTE"), ("IN", "BOOL"), ("OUT", "BOOL"), ("OUT", "BYTE"),
            ("OUT", "BYTE"), ("OUT", "BYTE"), ("OUT", "DINT")],
    "MAN": [("IN", "BOOL"), ("IN", "DINT"), ("OUT", "BYTE"), ("OUT", "DINT")],
    "LDPOS": [("IN", "BOOL"), ("IN", "DINT"), ("OUT", "BOOL"), ("OUT", "BYTE"),
              ("OUT", "DINT")],
    "ADV": [("IN", "BOOL"), ("OUT", "BOOL"), ("OUT", "BYTE"), ("OUT", "DINT")],
}


@pytest.mark.parametrize("name, params", [
    *((f"PTO{n}_{k}", p) for n in (0, 1) for k, p in MANUAL_INTERFACES.items()),
    *((f"PWM{n}_RUN", [("IN", "BOOL"), ("IN", "WORD"), ("IN", "WORD"), ("OUT", "BYTE")])
      for n in (0, 1))])
def test_the_library_interfaces_are_the_manuals(name, params):
    """library/pto_wizard.toml: directions and types in the manual's order,
    and every block has an implementation."""
    itf = interfaces()[name]
    assert [(p.dir, p.type) for p in itf.params] == params
    assert itf.library == "PTO_PWM_wizards"
    assert name in wz.NAMES


# -- RUN -----------------------------------------------------------------------
def test_a_relative_profile_without_ramps_ends_at_its_exact_time():
    """Steps 1000 pulses at 5000/s (200 µs) and 500 at 1000/s (1000 µs):
    1500 pulses, the end 700 ms after START; Done, C_Pos (HSC0 mode 12),
    SM66.7 and one PTO-complete event at the end."""
    plc = load("RUN")
    plc.scan()
    assert (plc["M2.0"], plc["VB0"]) == (1, 0)        # CTRL initialised, idle
    t0 = pulse(plc, "M0.2")
    assert plc.pulse[0].trains[-1].end == t0 + 1000 * 200 + 500 * 1000
    assert (plc["M2.1"], plc["SM66.7"]) == (0, 0)
    plc.scan()                                       # CTRL runs before RUN: busy next scan
    assert plc["M2.0"] == 0
    plc.run("0.39s")
    assert plc["VB8"] == 1 and plc["VD10"] == 1000 + (plc.now_us - 10_000 - t0 - 200_000) \
        // 1000 + 1                                     # C_Step 1, C_Pos of the last scan
    plc.run("0.31s")
    assert (plc["M2.1"], plc["VB2"], plc["VD10"], plc["VD4"]) == (1, 0, 1500, 1500)
    assert (plc["SM66.7"], plc["VW60"], sent(plc)) == (1, 1, 1500)
    assert plc["HC0"] == 1500


def test_a_ramped_profile_sends_exactly_its_steps_pulses():
    """With ramps the steps' pulses are still exact (the ramps lie inside
    the steps) and the acceleration 200 -> 5000 /s takes about the linear
    ramp's time (4800 / 19800 x 500 ms = 121.2 ms)."""
    plc = load("RUN", accel=500, decel=500)
    plc.scan()
    t0 = pulse(plc, "M0.2")
    assert ramp_pulses(200, 5000, load_plant(plant(500, 500)).pto[0], decel=False) == 315
    # the 316th pulse is the first at 5000/s: the ramp's end (123.586 ms)
    assert plc.pulse[0].time_of_pulse(316) - t0 == pytest.approx(121_212, rel=0.02)
    assert plc.pulse[0].pulse_in_progress(plc.pulse[0].time_of_pulse(316)).c0 == 200
    plc.run("3s")
    assert (plc["M2.1"], plc["VD10"], sent(plc), plc["VW60"]) == (1, 1500, 1500, 1)


def test_a_ramp_is_cut_in_pieces_of_twenty_percent_linear_in_cycle():
    """plan.ramp: speeds 1000, 1200, 1440, 1728, 2000; pulses up to v:
    round((v² − 1000²) / 2a) with a = 1000/s per 100 ms -> 22, 54, 99, 150;
    inside a piece Δ = round((c_b − c_a) / n), the first cycle c_a + Δ/2."""
    cfg = PtoConfig(0, max_speed=2000, ss_speed=1000, accel_ms=100, decel_ms=100)
    trains = ramp(1000, 2000, cfg, 3)
    assert [tr.count for tr in trains] == [22, 32, 45, 51]
    # cycles 1000, 833, 694, 579, 500 µs: Δ = round(−167/22), round(−139/32),
    # round(−115/45), round(−79/51); halves of Δ rounded up
    assert [cycle_us(v) for v in (1000, 1200, 1440, 1728, 2000)] == [1000, 833, 694, 579, 500]
    assert [(tr.c0, tr.delta) for tr in trains] == [(996, -8), (831, -4), (693, -3), (578, -2)]
    assert {tr.segment for tr in trains} == {3}


def test_abort_decelerates_from_the_pulse_in_progress():
    """Abort at t: the pulse in progress completes, then the stop ramp from
    its speed (1000/s) to SS_SPEED 500/s at 500/s per 100 ms: round((1000² −
    500²) / (2 · 5000)) = 75 pulses, about 100 ms."""
    text = ("[pto.0]\nmax_speed = 1000\nss_speed = 500\ndecel_ms = 100\nhsc = true\n"
            "[[pto.0.profile]]\nmode = \"relative\"\nsteps = [ { speed = 1000, pulses = 5000 } ]\n")
    plc = load("RUN", plant_text=text)
    plc.scan()
    t0 = pulse(plc, "M0.2")
    plc.run("0.1s")
    ta = pulse(plc, "M0.3")                          # 100 pulses have risen by ta - 1
    before = (ta - t0) // 1000 + 1                   # the one rising at ta included
    end = plc.pulse[0].trains[-1].end
    assert end - (ta + 1000) == pytest.approx(100_000, rel=0.02)
    plc.run("0.3s")
    assert sent(plc) == before + 75 and plc["VD10"] == before + 75
    assert (plc["M2.1"], plc["VW60"]) == (1, 1)     # Done; the stop ends as a PTO end


# -- CTRL stops ----------------------------------------------------------------
def test_i_stop_stops_the_pulses_at_once():
    """I_STOP at t: the pulses rose by t are all that is sent; SM66.5 (aborted)
    and idle, no PTO-complete event, Done of RUN and CTRL."""
    plc = load("RUN")
    plc.scan()
    t0 = pulse(plc, "M0.2")
    plc.run("0.05s")
    ts = pulse(plc, "M0.0")
    assert sent(plc) == (ts - t0) // 200 + 1 == 301
    assert (plc["SM66.5"], plc["SM66.7"], plc["VW60"]) == (1, 1, 0)
    assert (plc["M2.0"], plc["M2.1"], plc["VD4"]) == (1, 1, 301)


def test_d_stop_stops_after_the_pulse_in_progress_without_ramp_and_refuses_starts():
    """decel_ms = 0: D_STOP ends the motion with the pulse in progress (it
    ends at ts + 200 µs, inside the scan: idle and event 19 by the scan's
    end); a START while D_STOP is on is refused with Error 7."""
    plc = load("RUN")
    plc.scan()
    t0 = pulse(plc, "M0.2")
    plc.run("0.05s")
    ts = plc.now_us
    plc["M0.1"] = 1
    plc.scan()
    assert (plc["SM66.7"], plc["SM66.5"], plc["VW60"]) == (1, 0, 1)
    plc["M0.2"] = 1
    plc.scan()
    assert plc["VB2"] == wz.STOP_INPUT == 7
    assert sent(plc) == (ts - t0) // 200 + 1
    assert any("Error 7" in d.message for d in plc.diagnostics)


# -- continuous + ADV ----------------------------------------------------------
def test_adv_ends_a_continuous_profile_after_its_stop_pulses():
    """Profile 1: 1000/s without end; ADV at ta: the pulse rising at ta, then
    exactly stop_pulses = 300 more, the last ending at ta + 1 ms + 300 ms."""
    plc = load("RUN", "ADV")
    plc["VB1"] = 1
    plc.scan()
    t0 = pulse(plc, "M0.2")
    plc.run("1s")
    assert plc["M2.1"] == 0 and plc["VB3"] == 1
    ta = pulse(plc, "M0.6")
    assert plc.pulse[0].trains[-1].end == ta + 1000 + 300_000
    plc.run("0.4s")
    assert sent(plc) == (ta - t0) // 1000 + 1 + 300
    assert (plc["M2.3"], plc["M2.1"], plc["VB16"], plc["VW60"]) == (1, 1, 0, 1)


def test_adv_without_stop_pulses_is_refused():
    plc = load("RUN", "ADV")
    plc["VB1"] = 2
    plc.scan()
    pulse(plc, "M0.2")
    pulse(plc, "M0.6")
    assert plc["VB16"] == wz.NO_ADV and plc.pulse[0].trains


# -- MAN -----------------------------------------------------------------------
def test_manual_mode_changes_speed_and_stops_after_the_pulse_in_progress():
    """RUN at 1000/s from t0; Speed 2000 at t1 = t0 + 100 ms (the pulse rising
    at t1 completes, then 500 µs pulses); RUN off at t2 = t1 + 100 ms: the
    pulse rising at t2 is the last.  101 + 199 pulses, the end at t2 + 500."""
    plc = load("MAN", "RUN")
    plc.scan()
    plc["VD20"] = 1000
    plc["M0.4"] = 1
    t0 = plc.now_us
    plc.run("0.1s")
    plc["VD20"] = 2000
    t1 = plc.now_us
    assert t1 == t0 + 100_000
    plc.scan()
    # manual mode refuses RUN
    plc["M0.2"] = 1
    plc.run("0.09s")
    plc["M0.2"] = 0
    assert plc["VB2"] == wz.MANUAL
    t2 = plc.now_us
    plc["M0.4"] = 0
    plc.scan()                                      # the last pulse ends at t2 + 500 µs
    assert plc.pulse[0].pulses_until(t2 + 499) == 300 and not plc.pulse[0].trains
    plc.run("0.1s")
    assert sent(plc) == 101 + 199 == plc["VD24"]
    assert (plc["VB14"], plc["VW60"]) == (0, 1)


def test_manual_speed_outside_the_configured_range_is_refused():
    plc = load("MAN")
    plc.scan()
    plc["VD20"] = 100                                # below ss_speed 200
    plc["M0.4"] = 1
    plc.scan()
    assert plc["VB14"] == wz.BAD_SPEED and not plc.pulse[0].trains


def test_manual_stop_with_a_ramp_sends_the_ramps_pulses():
    """decel 500 ms per 19800/s: from 2000/s round((2000² − 200²) · 500 /
    (2000 · 19800)) = 50 pulses after the pulse in progress."""
    plc = load("MAN", accel=500, decel=500)
    plc.scan()
    plc["VD20"] = 2000
    plc["M0.4"] = 1
    plc.run("1s")
    t2 = plc.now_us
    n = plc.pulse[0].pulses_until(t2)
    plc["M0.4"] = 0
    plc.run("1s")
    assert sent(plc) == n + 50 and not plc.pulse[0].trains


# -- LDPOS ---------------------------------------------------------------------
def test_ldpos_loads_the_counter_and_counting_goes_on_from_there():
    plc = load("RUN", "LDPOS")
    plc.scan()
    plc["VD30"] = -5000
    pulse(plc, "M0.5")
    plc.scan()                                       # CTRL (before LDPOS) reads it next scan
    assert (plc["M2.2"], plc["VB15"], plc["VD34"], plc["VD4"]) == (1, 0, -5000, -5000)
    pulse(plc, "M0.2")
    plc.run("1s")
    assert plc["VD4"] == -5000 + 1500 and plc["HC0"] == -3500
    pulse(plc, "M0.2")
    pulse(plc, "M0.5")                              # refused while the motion runs
    assert plc["VB15"] == wz.BUSY and plc["M2.2"] == 0


def test_ldpos_without_the_hsc_option_is_refused_and_c_pos_is_0():
    plc = load("RUN", "LDPOS", hsc=False)
    plc.scan()
    pulse(plc, "M0.5")
    assert plc["VB15"] == wz.NO_HSC
    pulse(plc, "M0.2")
    plc.run("1s")
    assert (plc["VD10"], plc["VD4"], sent(plc)) == (0, 0, 1500)


# -- refusals ------------------------------------------------------------------
def test_refusals_busy_bad_profile_and_not_initialised():
    """A second RUN call site while the first one's motion runs: Error 3; a
    profile number past the table: 5; RUN before CTRL ever ran: 2."""
    two = program("CTRL", "RUN", sbrs="") .replace(
        "END_ORGANIZATION_BLOCK",
        "Network 9\nLD SM0.0\nCALL PTO0_RUN, M5.0, VB70, M5.1, M5.2, VB71, VB72, VB73, VD74\n"
        "END_ORGANIZATION_BLOCK")
    plc = plcrt.load(two, plant=load_plant(plant()))
    plc.scan()
    pulse(plc, "M0.2")
    pulse(plc, "M5.0")
    assert plc["VB71"] == wz.BUSY and plc["VB2"] == 0
    plc.run("1s")
    plc["VB70"] = 7
    pulse(plc, "M5.0")
    assert plc["VB71"] == wz.BAD_PROFILE
    no_ctrl = plcrt.load(program("RUN"), plant=load_plant(plant()))
    pulse(no_ctrl, "M0.2")
    assert no_ctrl["VB2"] == wz.NOT_INIT and not no_ctrl.pulse[0].trains


def test_without_a_plant_the_blocks_load_warn_and_report_error_1():
    plc = plcrt.load(program("CTRL", "RUN", "MAN", "PWM"))
    warns = [d.message for d in plc.diagnostics if d.severity == "warning"]
    # once per output, however many of its blocks the program calls
    assert sum("must come from the plant file ([pto.0])" in w for w in warns) == 1
    assert any("must come from the plant file ([pwm.1])" in w for w in warns)
    plc["M0.4"] = 1
    plc["M1.0"] = 1
    pulse(plc, "M0.2")
    assert (plc["VB0"], plc["VB2"], plc["VB14"], plc["VB54"]) == (1, 1, 1, 1)
    assert not plc.pulse[0].running and not plc.pulse[1].running


def test_a_max_speed_above_the_cpus_output_warns_at_load_and_refuses():
    plc = plcrt.load(program("CTRL", "RUN"), cpu="CPU224",
                     plant=load_plant(plant(mx=50000)))
    assert any("above the 20000 pulses/s" in d.message for d in plc.diagnostics)
    plc.scan()
    pulse(plc, "M0.2")
    assert plc["VB2"] == wz.TOO_FAST


# -- PWM -----------------------------------------------------------------------
def test_pwm_runs_in_the_wizards_time_base_and_updates_synchronously():
    """time_base "ms": Cycle 10, Duty_Cycle 3 -> 10 ms cycle, 3 ms high; a new
    width takes effect at the end of the running cycle; RUN off: off."""
    text = plant() + "[pwm.1]\ntime_base = \"ms\"\n"
    plc = plcrt.load(program("PWM"), plant=load_plant(text), scan_ms=7)
    plc["VW50"], plc["VW52"] = 10, 3
    plc["M1.0"] = 1
    t0 = plc.now_us
    plc.scan()
    po = plc.pulse[1]
    assert po.pwm == (t0, 10_000, 3_000) and plc["VB54"] == 0
    assert [po.level(t0 + dt) for dt in (0, 2_999, 3_000, 9_999, 10_000)] == [1, 1, 0, 0, 1]
    plc["VW52"] = 6
    plc.scan()                                      # at t0 + 7 ms: applied at t0 + 10 ms
    assert po.pwm == (t0 + 10_000, 10_000, 6_000) and po.pwm_next is None
    plc["M1.0"] = 0
    plc.scan()
    assert not po.running and plc["Q0.1"] == 0


def test_pwm_cycle_below_the_outputs_minimum_is_refused():
    text = plant() + "[pwm.1]\ntime_base = \"us\"\n"
    plc = plcrt.load(program("PWM"), plant=load_plant(text))
    plc["VW50"], plc["VW52"] = 20, 10
    pulse(plc, "M1.0")
    assert plc["VB54"] == wz.BAD_CYCLE and not plc.pulse[1].running


# -- recognition of the export's protected subroutines ------------------------
def sbr(name: str, number: int, params: list[tuple[str, str, str]], body: str = "") -> str:
    out = [f"SUBROUTINE_BLOCK {name}:SBR{number}", "TITLE=generated by a wizard"]
    for section in ("IN", "OUT"):
        decls = [p for p in params if p[0] == section]
        if decls:
            out.append(f"VAR_{'INPUT' if section == 'IN' else 'OUTPUT'}")
            out += [f"{n}:{t};" for _s, n, t in decls]
            out.append("END_VAR")
    out.append("BEGIN")
    if body:
        out += ["Network 1", *body.splitlines()]
    out.append("END_SUBROUTINE_BLOCK")
    return "\n".join(out) + "\n"


def protected(name: str, number: int) -> str:
    kind = name.split("_")[1]
    types = MANUAL_INTERFACES.get(kind) if name.startswith("PTO") else \
        [("IN", "BOOL"), ("IN", "WORD"), ("IN", "WORD"), ("OUT", "BYTE")]
    # parameter names differ from the manual's: only order and types count
    return sbr(name, number, [(d, f"p{i}", t) for i, (d, t) in enumerate(types)])


def test_an_export_with_protected_wizard_blocks_runs_the_emulation():
    """The wizard's subroutines as an export holds them (interface, empty
    body), called by name and by SBR number: the blocks run."""
    sbrs = "".join(protected(n, i) for i, n in enumerate(
        ["PTO0_CTRL", "PTO0_RUN", "PTO0_MAN", "PTO0_LDPOS", "PTO0_ADV", "PWM1_RUN"], 1))
    text = program("CTRL", "RUN", "MAN", "LDPOS", "ADV", "PWM", sbrs=sbrs).replace(
        "CALL PTO0_RUN,", "CALL SBR2,")
    plc = plcrt.load(text, plant=load_plant(plant() + "[pwm.1]\ntime_base = \"us\"\n"))
    assert not any("own subroutine runs" in d.message for d in plc.diagnostics)
    assert sum("emulated from the plant's [pto.0]" in d.message for d in plc.diagnostics) == 1
    plc.scan()
    t0 = pulse(plc, "M0.2")
    assert plc.pulse[0].trains[-1].end == t0 + 700_000
    plc.run("1s")
    assert (plc["M2.1"], plc["VD10"]) == (1, 1500)


def test_a_wizard_name_with_another_interface_or_a_body_runs_its_own_code():
    """Named PTO0_RUN but with two inputs only, or PTO0_CTRL with
    instructions: the program's subroutine runs, with one warning each."""
    other = sbr("PTO0_RUN", 1, [("IN", "a", "BOOL"), ("IN", "b", "BYTE")],
                "LD SM0.0\nINCW VW90")
    body = sbr("PTO0_CTRL", 2, [(d, f"p{i}", t) for i, (d, t) in
                                enumerate(MANUAL_INTERFACES["CTRL"])], "LD SM0.0\nINCW VW92")
    text = program(sbrs=other + body).replace(
        "END_ORGANIZATION_BLOCK", "Network 8\nLD SM0.0\nCALL PTO0_RUN, M0.2, VB1\n"
        "CALL PTO0_RUN, M0.2, VB1\nCALL PTO0_CTRL, M0.0, M0.1, M2.0, VB0, VD4\n"
        "END_ORGANIZATION_BLOCK")
    plc = plcrt.load(text, plant=load_plant(plant()))
    own = [d.message for d in plc.diagnostics if "own subroutine runs" in d.message]
    assert len(own) == 2
    assert any("not the library's IN BOOL, IN BYTE, IN BOOL" in m for m in own)
    assert any("has instructions" in m for m in own)
    plc.scan(3)
    assert (plc["VW90"], plc["VW92"]) == (6, 3)
    assert not plc.pulse[0].trains


def test_a_fork_mid_motion_continues_the_same_motion():
    plc = load("RUN")
    plc.scan()
    pulse(plc, "M0.2")
    plc.run("0.3s")
    twin = plc.fork()
    plc.run("0.5s")
    twin.run("0.5s")
    assert (twin["M2.1"], twin["VD10"], twin["VW60"]) == (plc["M2.1"], plc["VD10"],
                                                          plc["VW60"]) == (1, 1500, 1)


# -- plant keys ----------------------------------------------------------------
@pytest.mark.parametrize("text, key", [
    ("[pto.2]\nmax_speed = 1000\nss_speed = 100\n", "pto.2"),
    ("[pto.0]\nmax_speed = 1000\nss_speed = 100\nspeed = 3\n", "unknown key(s) speed"),
    ("[pto.0]\nss_speed = 100\n", "pto.0.max_speed is missing"),
    ("[pto.0]\nmax_speed = 1000\nss_speed = 2000\n", "pto.0.ss_speed"),
    ("[pto.0]\nmax_speed = 200000\nss_speed = 100\n", "pto.0.max_speed"),
    ("[pto.0]\nmax_speed = 1000\nss_speed = 100\naccel_ms = -1\n", "pto.0.accel_ms"),
    ("[pto.0]\nmax_speed = 1000\nss_speed = 100\nhsc = 1\n", "pto.0.hsc"),
    ("[pto.0]\nmax_speed = 1000\nss_speed = 100\n[[pto.0.profile]]\nmode = \"absolute\"\n",
     "pto.0.profile[0].mode"),
    ("[pto.0]\nmax_speed = 1000\nss_speed = 100\n[[pto.0.profile]]\nmode = \"relative\"\n"
     "steps = [ { speed = 5000, pulses = 10 } ]\n", "pto.0.profile[0].steps[0].speed"),
    ("[pto.0]\nmax_speed = 1000\nss_speed = 100\naccel_ms = 1000\n[[pto.0.profile]]\n"
     "mode = \"relative\"\nsteps = [ { speed = 1000, pulses = 10 } ]\n",
     "pto.0.profile[0].steps[0].pulses"),
    ("[pto.0]\nmax_speed = 1000\nss_speed = 100\n[[pto.0.profile]]\nmode = \"relative\"\n"
     "steps = [ { speed = 500, pulses = 10, dir = 1 } ]\n", "unknown key(s) dir"),
    ("[pto.0]\nmax_speed = 1000\nss_speed = 100\ndecel_ms = 1000\n[[pto.0.profile]]\n"
     "mode = \"continuous\"\nspeed = 1000\nstop_pulses = 5\n", "profile[0].stop_pulses"),
    ("[pwm.0]\ntime_base = \"s\"\n", "pwm.0.time_base"),
    ("[pwm.0]\ntime_base = [1]\n", "pwm.0.time_base"),
    ("[pto.0]\nmax_speed = 1000\nss_speed = 100\n[[pto.0.profile]]\nmode = [1]\n",
     "pto.0.profile[0].mode"),
    ("pto = [1]\n", "[pto] must be a table of outputs"),
    ("[pwm.1]\ntime_base = \"us\"\n[pto.1]\nmax_speed = 1000\nss_speed = 100\n",
     "configured as a PTO and as a PWM"),
    ("[ptos.0]\n", "unknown key(s) ptos"),
])
def test_plant_mistakes_are_located_config_errors(text, key):
    with pytest.raises(plcrt.PlcConfigError) as e:
        load_plant(text, file="machine.toml")
    assert "machine.toml" in str(e.value) and key in str(e.value)


def test_plant_keys_read_into_the_configuration():
    cfg = load_plant(plant(accel=500, decel=400) + "[pwm.1]\ntime_base = \"ms\"\n")
    pto = cfg.pto[0]
    assert (pto.max_speed, pto.ss_speed, pto.accel_ms, pto.decel_ms, pto.hsc) == \
        (20000, 200, 500, 400, True)
    assert [p.mode for p in pto.profiles] == ["relative", "continuous", "continuous"]
    assert [(s.speed, s.pulses) for s in pto.profiles[0].steps] == [(5000, 1000), (1000, 500)]
    assert (pto.profiles[1].speed, pto.profiles[1].stop_pulses) == (1000, 300)
    assert cfg.pwm[1].unit == 1000


def test_d_stop_holds_a_manual_motion_that_run_keeps_asking_for():
    """MAN's RUN stays on while D_STOP stops the motion: the stop completes
    and MAN reports Error 7 instead of ramping up again."""
    plc = load("MAN")
    plc.scan()
    plc["VD20"] = 1000
    plc["M0.4"] = 1
    plc.run("0.1s")
    ts = plc.now_us
    plc["M0.1"] = 1
    plc.run("0.1s")
    assert plc["VB14"] == wz.STOP_INPUT and not plc.pulse[0].trains
    assert sent(plc) == plc.pulse[0].pulses_until(ts) == 101


def test_the_ladder_view_draws_wizard_calls_with_their_pins(tmp_path, capsys):
    """A library call (PTO0_RUN, no subroutine) and a NAME:SBRn call of a
    protected subroutine: boxes with the interface's pin names."""
    from plcrt.cli import main
    text = program("RUN", sbrs=protected("PTO0_CTRL", 1)).replace(
        "END_ORGANIZATION_BLOCK", "Network 9\nLD SM0.0\n"
        "CALL PTO0_CTRL:SBR1, M0.0, M0.1, M2.0, VB0, VD4\nEND_ORGANIZATION_BLOCK")
    path = tmp_path / "wizard.awl"
    path.write_text(text, encoding="utf-8")
    assert main(["show", str(path)]) == 0
    out = capsys.readouterr().out
    assert "│     PTO0_RUN     │" in out and "─┤START         Done├─M2.1" in out
    assert "PTO0_CTRL:SBR1" in out and "─┤p0            p2├─M2.0" in out


def test_abort_in_the_last_pulses_of_a_relative_profile_ends_as_planned():
    """5000 pulses at 1000/s whose last 75 are the stop ramp: an Abort when
    fewer pulses are left than a new stop would take changes nothing (the
    move never goes beyond its own end)."""
    text = ("[pto.0]\nmax_speed = 1000\nss_speed = 500\ndecel_ms = 100\nhsc = true\n"
            "[[pto.0.profile]]\nmode = \"relative\"\nsteps = [ { speed = 1000, pulses = 5000 } ]\n")
    plc = load("RUN", plant_text=text)
    plc.scan()
    pulse(plc, "M0.2")
    end = plc.pulse[0].trains[-1].end
    plc.run("4.94s")
    assert 4925 < sent(plc) < 5000
    pulse(plc, "M0.3")
    assert plc.pulse[0].trains[-1].end == end
    plc.run("0.2s")
    assert (sent(plc), plc["M2.1"], plc["VW60"]) == (5000, 1, 1)


def test_the_sample_program_runs_its_profile_to_the_end():
    """programs/events/pto_wizard.awl with its plant: 34000 pulses counted
    on HSC0, the last step 1, Done and one PTO-complete routine; the ramps
    (200 ms per 19800/s) lie inside the steps."""
    from pathlib import Path
    events = Path(__file__).resolve().parents[2] / "programs" / "events"
    plc = plcrt.load(events / "pto_wizard.awl", plant=events / "pto_wizard_plant.toml")
    plc["M0.0"] = 1
    plc.run("1s")
    assert (plc["VB113"], plc["M10.1"]) == (0, 0) and 0 < plc["VD104"] < 30000
    plc.run("5s")
    assert (plc["VD104"], plc["VB113"], plc["M10.1"], plc["VW120"], plc["VB111"]) == \
        (34000, 1, 1, 1, 0)


def test_pto1_counts_on_hsc3_and_a_routine_starts_a_motion_at_its_own_time():
    """PTO1_RUN called in a timed interrupt routine (every 5 ms): the motion
    starts at the routine's time, not at a scan start; C_Pos is HSC3's CV."""
    text = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD SM0.1
MOVB 5, SMB34
ATCH INT_1, 10
ENI
Network 2
LD SM0.0
CALL PTO1_CTRL, M0.0, M0.1, M2.0, VB0, VD4
END_ORGANIZATION_BLOCK
INTERRUPT_BLOCK INT_1:INT1
BEGIN
Network 1
LD SM0.0
CALL PTO1_RUN, M0.2, VB1, M0.3, M2.1, VB2, VB3, VB8, VD10
END_INTERRUPT_BLOCK
"""
    plc = plcrt.load(text, plant=load_plant(plant().replace("pto.0", "pto.1")))
    plc.scan()                                       # t = 0; routines at 5 and 10 ms
    plc["M0.2"] = 1
    plc.scan()                                       # the routine at 15 ms starts it
    plc["M0.2"] = 0
    po = plc.pulse[1]
    assert po.trains[0].start == 15_000 and po.trains[-1].end == 15_000 + 700_000
    plc.run("1s")
    assert (plc["VD4"], plc["HC3"], plc["M2.1"]) == (1500, 1500, 1)


def test_a_held_start_runs_the_profile_again_after_each_end():
    """START is a level (the manual asks for an edge for that reason): held
    on, the 700 ms profile runs at 0, then again from the first call after
    its end; while it runs START changes nothing."""
    plc = load("RUN")
    plc.scan()
    plc["M0.2"] = 1
    t0 = plc.now_us
    plc.scan()
    first = plc.pulse[0].trains[-1].end
    assert first == t0 + 700_000
    plc.run("0.7s")                                  # the scan at t0 + 700 ms starts it again
    assert plc.pulse[0].trains[0].start == t0 + 700_000 and plc["VW60"] == 1
    assert sent(plc) == 1500 + 51                    # 200 µs pulses up to t0 + 710 ms


def test_a_counter_the_program_defined_otherwise_gives_error_11():
    """HSC0 in mode 0 from the program before PTO0_CTRL runs: CTRL reports
    Error 11, C_Pos stays 0, LDPOS is refused with 11; the motion runs."""
    text = program("CTRL", "RUN", "LDPOS").replace(
        "ATCH INT_0, 19", "ATCH INT_0, 19\nHDEF 0, 0")
    plc = plcrt.load(text, plant=load_plant(plant()))
    plc.scan()
    pulse(plc, "M0.2")
    plc.run("1s")
    pulse(plc, "M0.5")
    assert (plc["VB0"], plc["VD4"], plc["VB15"], sent(plc)) == (wz.COUNTER, 0, wz.COUNTER,
                                                                 1500)
    assert any("HSC0 has mode 0" in d.message for d in plc.diagnostics)


@pytest.mark.parametrize("n_profiles, n_steps, ok", [(32, 16, True), (33, 1, False),
                                                       (1, 17, False)])
def test_the_plant_takes_32_profiles_of_16_steps(n_profiles, n_steps, ok):
    steps = ", ".join("{ speed = 500, pulses = 10 }" for _ in range(n_steps))
    text = "[pto.0]\nmax_speed = 1000\nss_speed = 100\n" + \
        f"[[pto.0.profile]]\nmode = \"relative\"\nsteps = [ {steps} ]\n" * n_profiles
    if ok:
        assert len(load_plant(text).pto[0].profiles) == n_profiles
    else:
        with pytest.raises(plcrt.PlcConfigError):
            load_plant(text)
