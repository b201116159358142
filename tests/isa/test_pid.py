"""The PID loop instruction (plcrt.isa.pid, plcrt.engine.pid; S7-200 System
Manual, "PID Loop instruction"): the equation term by term, the output
limits with the bias adjusted against windup, the loop types by their
parameters, the manual -> automatic change, math errors, and a loop closed
over the plant's first-order process."""

from __future__ import annotations

import math
import struct
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import plcrt
from plcrt.errors import PlcCompileError

ROOT = Path(__file__).resolve().parents[2]

OB1 = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     I0.0
PID    VB100, 0
END_ORGANIZATION_BLOCK
"""


def f32(x: float) -> float:
    return struct.unpack(">f", struct.pack(">f", x))[0]


def loop(pv: float, sp: float, m: float, kc: float, ts: float, ti: float, td: float,
         mx: float, pv1: float, *, auto_before: bool = True) -> plcrt.Plc:
    """One execution in automatic (the loop was in automatic the scan before,
    so no bumpless transfer), the table as given."""
    plc = plcrt.load(OB1)
    if auto_before:
        plc.pid.enabled[0] = True
    for off, x in zip(range(100, 136, 4), (pv, sp, m, kc, ts, ti, td, mx, pv1)):
        plc.write(f"VD{off}", float(x))
    plc.write("I0.0", 1)
    plc.scan()
    return plc


def table(plc: plcrt.Plc) -> dict[str, float]:
    names = ("pv", "sp", "m", "kc", "ts", "ti", "td", "mx", "pv1")
    return {n: plc.read(f"VD{100 + 4 * i}", "REAL") for i, n in enumerate(names)}


def expected(pv, sp, kc, ts, ti, td, mx, pv1):
    """The manual's equation, written out independently."""
    e = sp - pv
    g = kc if kc else 1.0
    mp = kc * e
    mi = mx if math.isinf(ti) else g * ts / (ti * 60) * e + mx
    md = g * td * 60 / ts * (pv1 - pv) if td else 0.0
    m = mp + mi + md
    if m > 1:
        m, mi = 1.0, 1.0 - (mp + md)
    elif m < 0:
        m, mi = 0.0, -(mp + md)
    return m, min(1.0, max(0.0, mi))


CASES = [
    # pv,  sp,  m,   kc,   ts,  ti,        td,   mx,  pv1     what
    (0.4, 0.6, 0.3, 0.5, 0.1, 0.2, 0.0, 0.3, 0.4),            # PI
    (0.4, 0.6, 0.3, 0.5, 0.1, math.inf, 0.0, 0.3, 0.4),       # P only: Ti = INF
    (0.45, 0.6, 0.3, 0.5, 0.2, 0.2, 0.01, 0.3, 0.40),         # PID, D on the PV change
    (0.4, 0.6, 0.3, 0.0, 0.1, 0.2, 0.0, 0.3, 0.4),            # Kc 0: I with gain 1.0
    (0.6, 0.4, 0.3, -0.5, 0.1, 0.2, 0.0, 0.3, 0.6),           # reverse acting
    (0.1, 0.9, 0.8, 2.0, 0.1, 0.5, 0.0, 0.8, 0.1),            # above 1.0: limited, MX adjusted
    (0.9, 0.1, 0.2, 2.0, 0.1, 0.5, 0.0, 0.2, 0.9),            # below 0.0: limited, MX adjusted
]


@pytest.mark.parametrize("pv, sp, m, kc, ts, ti, td, mx, pv1", CASES)
def test_one_execution_follows_the_manuals_equation(pv, sp, m, kc, ts, ti, td, mx, pv1):
    plc = loop(pv, sp, m, kc, ts, ti, td, mx, pv1)
    t = table(plc)
    args = [f32(x) for x in (pv, sp, kc, ts, ti, td, mx, pv1)]
    m_exp, mx_exp = expected(*args)
    assert t["m"] == pytest.approx(m_exp, abs=1e-6)
    assert t["mx"] == pytest.approx(mx_exp, abs=1e-6)
    assert t["pv1"] == f32(pv)                  # PVn-1 := PVn for the next execution
    assert 0.0 <= t["m"] <= 1.0 and 0.0 <= t["mx"] <= 1.0
    assert plc.read("SM1.1") == 0


def test_the_limit_case_keeps_the_output_at_one_and_the_bias_just_reaching_it():
    t = table(loop(0.1, 0.9, 0.8, 2.0, 0.1, 0.5, 0.0, 0.8, 0.1))
    assert t["m"] == 1.0
    # MP = 2.0 * 0.8 = 1.6 > 1, so the bias 1 - MP would be negative: 0.0
    assert t["mx"] == 0.0


def test_switching_to_automatic_is_bumpless():
    """Power flow 0 -> 1: SP = PV, PVn-1 = PV, MX = M, so the output stays."""
    plc = loop(0.35, 0.8, 0.42, 1.5, 0.1, 0.2, 0.05, 0.0, 0.0, auto_before=False)
    t = table(plc)
    assert t["sp"] == f32(0.35) and t["pv1"] == f32(0.35)
    assert t["m"] == pytest.approx(f32(0.42), abs=1e-7) and t["mx"] == t["m"]


def test_without_power_flow_nothing_is_computed_and_eno_is_0():
    plc = plcrt.load(OB1.replace("PID    VB100, 0", "PID    VB100, 0\nAENO\n= Q0.0"))
    plc.write("VD108", 0.25)
    plc.scan()
    assert plc.read("VD108", "REAL") == 0.25 and plc.read("Q0.0") == 0


@pytest.mark.parametrize("field, value", [(16, 0.0), (20, 0.0), (12, math.nan), (28, math.inf)])
def test_a_math_error_sets_sm1_1_and_leaves_the_outputs(field, value):
    plc = plcrt.load(OB1)
    plc.pid.enabled[0] = True
    for off, x in zip(range(100, 136, 4), (0.4, 0.6, 0.3, 0.5, 0.1, 0.2, 0.0, 0.3, 0.4)):
        plc.write(f"VD{off}", float(x))
    plc.write(f"VD{100 + field}", float(value))
    plc.write("I0.0", 1)
    plc.scan()
    assert plc.read("SM1.1") == 1
    assert plc.read("VD108", "REAL") == f32(0.3) and plc.read("VD132", "REAL") == f32(0.4)
    assert any("math error" in d.message for d in plc.diagnostics)


def test_pv_outside_zero_to_one_is_computed_and_reported():
    plc = loop(1.5, 0.5, 0.5, 0.1, 0.1, math.inf, 0.0, 0.5, 1.5)
    assert table(plc)["m"] == pytest.approx(0.4, abs=1e-6)
    assert any("outside the normalised range" in d.message for d in plc.diagnostics)


@pytest.mark.parametrize("ops, message", [
    ("VW100, 0", "V byte address"), ("MB0, 0", "V byte address"),
    ("VB10230, 0", "runs past the end of V memory"), ("VB100, 8", "loops 0..7"),
    ("VB100, VB0", "constant 0..7"),
])
def test_bad_operands_are_located_compile_errors(ops, message):
    with pytest.raises(PlcCompileError, match=message) as info:
        plcrt.load(OB1.replace("VB100, 0", ops))
    assert info.value.loc is not None and info.value.loc.line == 5


def test_two_boxes_with_one_loop_number_are_reported():
    plc = plcrt.load(OB1.replace("PID    VB100, 0", "PID    VB100, 0\nPID    VB200, 0"))
    assert any(d.code == "pid-loop" for d in plc.diagnostics)


@settings(max_examples=200, deadline=None)
@given(st.floats(0, 1), st.floats(0, 1), st.floats(0, 1), st.floats(-10, 10),
       st.floats(0.01, 10), st.floats(0.01, 100), st.floats(0, 10), st.floats(0, 1),
       st.floats(0, 1))
def test_property_the_output_and_bias_stay_in_range(pv, sp, m, kc, ts, ti, td, mx, pv1):
    t = table(loop(pv, sp, m, kc, ts, ti, td, mx, pv1))
    assert 0.0 <= t["m"] <= 1.0 and 0.0 <= t["mx"] <= 1.0


def test_a_pi_loop_closed_over_the_plant_process_settles_on_its_setpoint():
    """programs/pid: PI every 100 ms over gain 1, τ 5 s, 0.5 s dead time:
    within 1 % of the setpoint after 40 s, no steady-state error after 90 s,
    and a setpoint step is followed."""
    plc = plcrt.load(ROOT / "programs/pid/pid_loop.awl",
                     plant=ROOT / "programs/pid/pid_loop_plant.toml")
    plc.write("I0.0", 1)
    plc.run(40.0)
    assert abs(plc.read("AIW0") - 16000) < 160
    plc.run(50.0)
    assert abs(plc.read("AIW0") - 16000) <= 2
    plc.write("VW10", 24000)
    plc.run(90.0)
    assert abs(plc.read("AIW0") - 24000) <= 2
