"""The USS protocol library (USS_INIT, USS_CTRL, USS_RPM_x, USS_WPM_x)
against the plant's simulated MicroMaster-style drives over the port's
exact-timed serial model (plcrt.devices.uss; docs/uss.md).

Times: USS characters have 11 bits (8 data, even parity); k characters at
B baud sent from t end at t + ceil(k * 11 * 10^6 / B) µs.  A telegram is 16
characters; each goes out 2 characters after the line went quiet.
"""

from __future__ import annotations

from fractions import Fraction

import pytest

import plcrt
from plcrt.devices.plant import load_plant
from plcrt.devices.uss.drive import Drive, DriveConfig
from plcrt.devices.uss.library import POLL_MS, master_of
from plcrt.devices.uss.telegram import (STW, ZSW, Telegram, bcc, decode, encode, param_code,
                                        param_number, speed_word, word_speed)
from plcrt.errors import PlcConfigError

#: OB1: USS_INIT (Mode VB200, Baud VD204, Active VD208 -> M0.1, MB5); USS_CTRL
#: of drive VB212 (RUN M1.0, OFF2 M1.1, OFF3 M1.2, F_ACK M1.3, DIR M1.4,
#: Type VB213, Speed_SP VD214 -> Resp_R M2.0, Error MB6, Status VW218, Speed
#: VD220, Run_EN M2.1, D_Dir M2.2, Inhibit M2.3, Fault M2.4); the parameter
#: blocks share Drive VB240, Param VW242, Index VW244, EEPROM M4.7
PROGRAM = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     SM0.0
CALL   USS_INIT, VB200, VD204, VD208, M0.1, MB5
Network 2
LD     SM0.0
CALL   USS_CTRL, M1.0, M1.1, M1.2, M1.3, M1.4, VB212, VB213, VD214, M2.0, MB6, VW218, VD220, M2.1, M2.2, M2.3, M2.4
Network 3
LD     SM0.0
CALL   USS_RPM_W, M3.0, VB240, VW242, VW244, &VB400, M3.1, MB7, VW246
Network 4
LD     SM0.0
CALL   USS_RPM_D, M3.2, VB240, VW242, VW244, &VB400, M3.3, MB8, VD248
Network 5
LD     SM0.0
CALL   USS_RPM_R, M3.4, VB240, VW242, VW244, &VB400, M3.5, MB9, VD252
Network 6
LD     SM0.0
CALL   USS_WPM_W, M4.0, M4.7, VB240, VW242, VW244, VW256, &VB420, M4.1, MB10
Network 7
LD     SM0.0
CALL   USS_WPM_D, M4.2, M4.7, VB240, VW242, VW244, VD258, &VB420, M4.3, MB11
Network 8
LD     SM0.0
CALL   USS_WPM_R, M4.4, M4.7, VB240, VW242, VW244, VD262, &VB420, M4.5, MB12
END_ORGANIZATION_BLOCK
"""
#: a second USS_CTRL for drive 2: RUN M20.0, DIR M20.4 -> Resp_R M21.0, Error MB13 ...
SECOND = """Network 9
LD     SM0.0
CALL   USS_CTRL, M20.0, M20.1, M20.2, M20.3, M20.4, 2, 1, VD300, M21.0, MB13, VW304, VD306, M21.1, M21.2, M21.3, M21.4
END_ORGANIZATION_BLOCK
"""
#: (param block's XMT_REQ, Done, Error, Value) by block
READS = {"W": ("M3.0", "M3.1", "MB7", "VW246"), "D": ("M3.2", "M3.3", "MB8", "VD248"),
         "R": ("M3.4", "M3.5", "MB9", "VD252:REAL")}
WRITES = {"W": ("M4.0", "M4.1", "MB10", "VW256"), "D": ("M4.2", "M4.3", "MB11", "VD258"),
          "R": ("M4.4", "M4.5", "MB12", "VD262")}


def drive_toml(address: int = 1, **keys) -> str:
    body = {"address": address, "base_hz": 50.0, "ramp_up_s": 10.0, "ramp_down_s": 10.0,
            "off3_ramp_s": 1.0, "response_delay_ms": 2,
            "word": "{ 700 = 5, 731 = [1, 2, 3] }", "dword": "{ 2200 = 123456 }",
            "real": "{ 1082 = 50.0, 1120 = 10.0 }", "read_only": "[1082]"}
    body.update(keys)
    lines = ["[[port.0.uss.drive]]"]
    lines += [f"{k} = {v}" for k, v in body.items() if v is not None]
    return "\n".join(lines) + "\n"


def plant(*drives: str, head: str = "") -> str:
    return "[port.0.uss]\n" + head + "".join(drives or (drive_toml(),))


def load(text: str | None = None, baud: int = 9600, active: int = 0b10,
         program: str = PROGRAM, speed: float = 50.0, **kw) -> plcrt.Plc:
    plc = plcrt.load(program, plant=load_plant(text if text is not None else plant()),
                     scan_ms=1, **kw)
    plc["VB200"], plc["VD204"], plc["VD208"] = 1, baud, active
    plc["VB212"], plc["VB213"], plc["VD214"] = 1, 1, speed
    plc["M1.4"] = 1                                  # DIR 1: clockwise
    plc.scan()
    return plc


def drive(plc: plcrt.Plc, address: int = 1) -> Drive:
    return plc.ports[0].peer.drives[address]


def speed(plc: plcrt.Plc) -> float:
    return plc["VD220:REAL"]


def request(plc: plcrt.Plc, bits: tuple, scans: int = 300) -> tuple[int, int]:
    """XMT_REQ for one scan, then scans until Done: (Done, Error)."""
    req, done, err = bits[:3]
    plc[req] = 1
    plc.scan()
    plc[req] = 0
    for _ in range(scans):
        if plc[done]:
            break
        plc.scan()
    return plc[done], plc[err]


def read(plc: plcrt.Plc, kind: str, param: int, index: int = 0, drive_no: int = 1) -> tuple:
    plc["VB240"], plc["VW242"], plc["VW244"] = drive_no, param, index
    done, err = request(plc, READS[kind])
    return done, err, plc[READS[kind][3]]


def write(plc: plcrt.Plc, kind: str, param: int, value, index: int = 0,
          eeprom: int = 0) -> tuple[int, int]:
    plc["VB240"], plc["VW242"], plc["VW244"], plc["M4.7"] = 1, param, index, eeprom
    plc[WRITES[kind][3]] = value
    return request(plc, WRITES[kind])


# ---------------------------------------------------------------- telegrams
def test_telegram_bytes_hand_computed():
    """Read task 1 for P0700 of drive 3 with STW 16#047F and HSW 16#2000:
    02 0E 03 | 12 BC 00 00 00 00 00 00 | 04 7F 20 00 | BCC 16#FA
    (02^0E^03^12^BC^04^7F^20 = FA)."""
    t = Telegram(3, 0x1000 | 700, 0, 0, 0x047F, 0x2000)
    data = encode(t)
    assert data.hex().upper() == "020E0312BC000000000000047F2000FA"
    assert bcc(data[:-1]) == 0xFA and len(data) == 16
    assert decode(data) == (t, "")


@pytest.mark.parametrize("mutate, why", [
    (lambda d: b"\x03" + d[1:], "stx"), (lambda d: d[:-1], "length"),
    (lambda d: d[:1] + b"\x0c" + d[2:14], "lge"), (lambda d: d[:-1] + b"\x00", "bcc")])
def test_decode_names_what_is_wrong(mutate, why):
    """A wrong STX, a length LGE does not give, an LGE other than 14, a bad BCC."""
    data = encode(Telegram(1, 0, 0, 0, 0x047F, 0x4000))
    assert decode(mutate(data)) == (None, why)


def test_parameter_page_bit_and_speed_scaling():
    """P2200 index 3 is PNU 200 with IND 16#8003; -50 % is 16#E000 signed
    (MicroMaster 4) and 16#2000 as a magnitude (MicroMaster 3)."""
    assert param_code(2200, 3) == (200, 0x8003) and param_number(200, 0x8003) == 2200
    assert param_code(700, 0) == (700, 0)
    assert speed_word(-50.0, True) == 0xE000 and speed_word(-50.0, False) == 0x2000
    assert speed_word(100.0, True) == 0x4000 and speed_word(200.0, True) == 0x7FFF
    assert word_speed(0xE000, True) == -50.0 and word_speed(0xE000, False) == 350.0


# ---------------------------------------------------------------- USS_INIT
def test_init_takes_the_port_and_gives_it_back():
    """Mode 1 at 9600: SMB30 = 16#49 (even parity, 9600, freeport); Mode 0: PPI."""
    plc = load()
    assert (plc["M0.1"], plc["MB5"], plc["SMB30"]) == (1, 0, 0x49)
    assert plc.ports[0].owner is master_of(plc)
    plc["VB200"] = 0
    plc.scan()
    assert plc["SMB30"] == 0 and plc.ports[0].owner is None
    plc.scan()
    assert plc["MB6"] == 7                        # USS_CTRL: the port is not USS


@pytest.mark.parametrize("mode, baud, error", [(2, 9600, 16), (1, 9601, 18), (1, 300, 18)])
def test_init_parameter_errors(mode, baud, error):
    """Mode other than 0/1 is Error 16, a baud rate not 1200..115200 18."""
    plc = load()
    plc["VB200"] = 0
    plc.scan()
    plc["VB200"], plc["VD204"] = mode, baud
    plc.scan()
    assert (plc["M0.1"], plc["MB5"], plc["SMB30"]) == (1, error, 0)


def test_init_change_while_active_is_error_17():
    """Another Active mask while USS runs: Error 17; the same setting: Error 0."""
    plc = load()
    plc["VD208"] = 0b110
    plc.scan()
    assert plc["MB5"] == 17 and master_of(plc).active == [1]
    plc["VD208"] = 0b10
    plc.scan()
    assert plc["MB5"] == 0


SMART = PROGRAM.replace("CALL   USS_INIT, VB200, VD204, VD208",
                        "CALL   USS_INIT, VB200, VD204, VB201, VD208")


@pytest.mark.parametrize("cpu, port, error", [("CPU226", 1, 0), ("CPU226", 2, 23),
                                              ("CPU224", 1, 23)])
def test_smart_init_port_input(cpu, port, error):
    """The SMART USS_INIT (Port before Active): port 1 is SMB130; no port 2,
    nor port 1 on a one-port CPU (Error 23, plcrt's number)."""
    plc = plcrt.load(SMART, scan_ms=1, cpu=cpu)
    plc["VB200"], plc["VD204"], plc["VB201"], plc["VD208"] = 1, 19200, port, 2
    plc.scan()
    assert plc["MB5"] == error
    if not error:
        assert plc["SMB130"] == 0x45 and plc.ports[1].owner is master_of(plc)


# ---------------------------------------------------------------- timing
@pytest.mark.parametrize("baud, char, start, whole", [(9600, 1146, 2292, 18334),
                                                      (19200, 573, 1146, 9167)])
def test_telegram_times(baud, char, start, whole):
    """The first telegram goes out 2 characters after USS_INIT (t 0); 16
    characters of 11 bits; the drive answers 2 ms after the request's end;
    the response ends with its 16th character; the next telegram 2
    characters later."""
    plc = load(baud=baud)
    plc.run(0.2)
    log = master_of(plc).log
    first, second = log[0], log[1]
    assert (first["sent"], first["sent_end"]) == (start, start + whole)
    answer = start + whole + 2000
    assert first["first_char"] == answer + char
    assert first["last_char"] == first["finished"] == answer + whole
    assert second["sent"] == answer + whole + start
    assert first["error"] == second["error"] == 0
    assert plc.ports[0].peer.telegrams[0][0] == start + whole


def test_absent_drive_times_out_with_error_1():
    """Drive 3 is active but absent: no answer within the manual's poll time
    (50 ms at 9600) from the request's end is Error 1; the drive after it
    is polled 2 characters later."""
    plc = load(active=0b1010)
    plc["VB212"] = 3
    plc.run(0.3)
    log = master_of(plc).log
    lost = next(e for e in log if e["drive"] == 3)
    assert lost["error"] == 1 and lost["finished"] == lost["sent_end"] + POLL_MS[9600] * 1000
    after = log[log.index(lost) + 1]
    assert after["drive"] == 1 and after["sent"] == lost["finished"] + 2292
    assert plc["MB6"] == 1 and plc["M2.0"] == 0


def test_two_active_drives_are_polled_in_turn():
    """Active 2#110: drives 1 and 2 alternate, one telegram each; both USS_CTRL
    see responses (Resp_R) and run their drives."""
    program = PROGRAM.replace("END_ORGANIZATION_BLOCK\n", SECOND)
    plc = load(plant(drive_toml(1), drive_toml(2)), active=0b110, program=program)
    plc["VD300"] = 25.0
    plc["M1.0"], plc["M20.0"], plc["M20.4"] = 1, 1, 1
    seen = {"M2.0": 0, "M21.0": 0}
    for _ in range(400):
        plc.scan()
        for k in seen:
            seen[k] += plc[k]
    order = [e["drive"] for e in master_of(plc).log[:8]]
    assert order == [1, 2, 1, 2, 1, 2, 1, 2]
    assert seen["M2.0"] >= 4 and seen["M21.0"] >= 4
    assert drive(plc, 1).on and drive(plc, 2).on
    assert drive(plc, 2).sp == Fraction(25, 2) and drive(plc, 1).sp == 25


# ---------------------------------------------------------------- the drive
def test_ramp_reaches_the_setpoint_at_the_analytic_time():
    """RUN with 50 % of 50 Hz, 10 s ramp to 50 Hz: 25 Hz exactly 5 s after
    the telegram that switched the drive on; the first response after that
    reports 'at setpoint', Speed 50.0, Run_EN and D_Dir."""
    plc = load()
    plc["M1.0"] = 1
    plc.run(5.2)
    bus = plc.ports[0].peer
    on_t = next(t for t, data in bus.telegrams if decode(data)[0].stw & STW["on"])
    reached = on_t + 5_000_000
    zsw = [(t, decode(a)[0].stw) for t, a in bus.answers]
    first = next(t for t, z in zsw if z & ZSW["at_setpoint"])
    assert max(t for t, z in zsw if t < first) - 2000 < reached <= first - 2000
    assert drive(plc).f == 25
    assert (speed(plc), plc["M2.1"], plc["M2.2"], plc["M2.3"], plc["M2.4"]) == (50.0, 1, 1, 0, 0)
    assert plc["VW218"] & ZSW["at_setpoint"] and plc["MB6"] == 0


def test_drive_ramp_is_exact():
    """The drive alone: ON at 0 with 25 Hz; 1 µs before 5 s it is below, at 5 s exactly 25."""
    d = Drive(DriveConfig(1, ramp_up_s=10.0))
    d.control(0, 0x047F, 0x2000)
    d.advance(4_999_999)
    assert d.f == Fraction(25) - Fraction(5, 1_000_000) / 1
    d.advance(5_000_000)
    assert d.f == 25 and d.status() & ZSW["at_setpoint"]


def test_reverse_ramps_through_zero():
    """DIR 0 at 25 Hz: down to 0 in 5 s, up to -25 Hz in 5 s; D_Dir 0, Speed -50.0."""
    plc = load()
    plc["M1.0"] = 1
    plc.run(5.2)
    plc["M1.4"] = 0
    plc.run(5.1)
    assert drive(plc).f < 0 and not plc["M2.2"]
    plc.run(5.2)
    assert drive(plc).f == -25 and speed(plc) == -50.0 and plc["M2.2"] == 0


def test_run_off_ramps_down():
    """RUN 0 (OFF1) at 25 Hz: down the 10 s ramp, stopped 5 s later, Run_EN 0."""
    plc = load()
    plc["M1.0"] = 1
    plc.run(5.2)
    plc["M1.0"] = 0
    plc.run(2.5)
    assert 12 < drive(plc).f < 13 and plc["M2.1"] == 1
    plc.run(2.7)
    assert drive(plc).f == 0 and not drive(plc).on and plc["M2.1"] == 0 and plc["M2.3"] == 0


def test_off2_coasts_and_inhibits_until_run_is_off():
    """OFF2: the output is 0 at the next telegram (coast), Inhibit 1; RUN
    again does nothing until RUN was 0."""
    plc = load()
    plc["M1.0"] = 1
    plc.run(3.0)
    plc["M1.1"] = 1
    plc.run(0.1)
    assert drive(plc).f == 0 and plc["M2.1"] == 0 and plc["M2.3"] == 1
    assert not plc["VW218"] & ZSW["no_off2"]
    plc["M1.1"] = 0
    plc.run(0.5)
    assert drive(plc).f == 0 and plc["M2.3"] == 1
    plc["M1.0"] = 0
    plc.run(0.1)
    assert plc["M2.3"] == 0
    plc["M1.0"] = 1
    plc.run(1.0)
    assert drive(plc).on and drive(plc).f > 0


def test_off3_stops_on_the_fast_ramp():
    """OFF3 at 25 Hz with a 1 s OFF3 ramp (50 Hz/s): stopped 0.5 s after
    the telegram that carried it, not the 5 s of OFF1."""
    plc = load()
    plc["M1.0"] = 1
    plc.run(5.2)
    plc["M1.2"] = 1
    t0 = plc.now_us
    plc.run(0.3)
    assert 0 < drive(plc).f < 25
    plc.run(0.3)
    assert drive(plc).f == 0 and plc["M2.3"] == 1 and plc["M2.1"] == 0
    carried = next(t for t, data in plc.ports[0].peer.telegrams
                   if t >= t0 and not decode(data)[0].stw & STW["no_off3"])
    assert carried < t0 + 60_000


def test_fault_and_acknowledge():
    """A trip: Fault 1, Run_EN 0, the output 0; F_ACK clears the fault, the
    inhibit stays until RUN is 0; then RUN starts the drive again."""
    plc = load()
    plc["M1.0"] = 1
    plc.run(2.0)
    drive(plc).trip(7)
    plc.run(0.1)
    assert (plc["M2.4"], plc["M2.1"], plc["M2.3"]) == (1, 0, 1) and drive(plc).f == 0
    plc["M1.3"] = 1
    plc.run(0.1)
    assert (plc["M2.4"], plc["M2.3"]) == (0, 1) and not drive(plc).on
    plc["M1.3"], plc["M1.0"] = 0, 0
    plc.run(0.1)
    assert plc["M2.3"] == 0
    plc["M1.0"] = 1
    plc.run(1.0)
    assert drive(plc).on and plc["M2.1"] == 1


def test_type_0_micromaster_3_magnitudes():
    """Type 0 with a MicroMaster 3 drive: -50 % goes as 16#2000 with the
    reverse bit; the drive reports the magnitude, Speed is -50.0."""
    plc = load(plant(drive_toml(model='"mm3"')), speed=-50.0)
    plc["VB213"], plc["M1.0"] = 0, 1
    plc.run(10.5)
    tel = decode(plc.ports[0].peer.telegrams[-1][1])[0]
    assert tel.hsw == 0x2000 and tel.stw & STW["reverse"]
    assert drive(plc).f == -25 and speed(plc) == -50.0 and plc["M2.2"] == 0


@pytest.mark.parametrize("setup, error", [({"VB212": 40}, 6), ({"VB212": 5}, 19),
                                          ({"VD214": 250.0}, 9), ({"VB213": 3}, 5)])
def test_ctrl_input_errors(setup, error):
    """Drive 40 is Error 6, a drive not in Active 19, Speed_SP 250 % 9, Type 3 5."""
    plc = load()
    for k, v in setup.items():
        plc[k] = v
    plc.scan()
    assert plc["MB6"] == error


# ---------------------------------------------------------------- parameters
def test_parameter_reads():
    """USS_RPM_W P0700, USS_RPM_D P2200 (page bit), USS_RPM_R P1082, an
    indexed word P0731[2], r0021 (the actual frequency)."""
    plc = load()
    assert read(plc, "W", 700) == (1, 0, 5)
    assert read(plc, "D", 2200) == (1, 0, 123456)
    assert read(plc, "R", 1082) == (1, 0, 50.0)
    assert read(plc, "W", 731, 2) == (1, 0, 3)
    assert read(plc, "R", 21)[:2] == (1, 0)
    tel = decode(plc.ports[0].peer.telegrams[-1][1])[0]
    assert tel.task == 1 and tel.param == 21
    sent = [decode(d)[0] for _, d in plc.ports[0].peer.telegrams]
    assert any(t.task == 6 and t.ind == 2 and t.param == 731 for t in sent)
    assert any(t.pke & 0x7FF == 200 and t.ind == 0x8000 for t in sent)


@pytest.mark.parametrize("kind, param, index, error", [
    ("W", 1082, 0, 21), ("D", 700, 0, 22), ("W", 999, 0, 20), ("W", 731, 5, 20),
    ("W", 4000, 0, 15)])
def test_parameter_read_errors(kind, param, index, error):
    """A REAL read as a word is Error 21, a word read as a double word 22, an
    unknown parameter or a bad index the drive's error response (20), a
    parameter number past 3999 15."""
    plc = load()
    assert read(plc, kind, param, index)[:2] == (1, error)


def test_parameter_writes():
    """USS_WPM_W to RAM (task 2) and to EEPROM (task 14), USS_WPM_R of the
    ramp-up time (task 3) changes the ramp; a read-only parameter is refused."""
    plc = load()
    assert write(plc, "W", 700, 6) == (1, 0) and drive(plc).params[700] == ("word", 6)
    assert decode(plc.ports[0].peer.telegrams[-1][1])[0].task in (0, 2)
    assert write(plc, "W", 700, 7, eeprom=1) == (1, 0)
    assert drive(plc).eeprom[(700, 0)] == 7
    sent = [decode(d)[0] for _, d in plc.ports[0].peer.telegrams]
    assert [t.task for t in sent if t.task] == [2, 14]
    assert write(plc, "D", 2200, 99) == (1, 0) and drive(plc).params[2200][1] == 99
    assert write(plc, "R", 1120, 5.0) == (1, 0)
    assert drive(plc).params[1120] == ("real", 5.0) and drive(plc)._rate("ramp_up_s") == 10
    assert write(plc, "R", 1082, 40.0) == (1, 20)
    assert write(plc, "W", 731, 9, index=1) == (1, 0) and drive(plc).params[731][1] == [1, 9, 3]


def test_second_parameter_request_while_busy_is_error_8():
    """Two requests in one scan: the second USS_RPM is Error 8 at once; the
    first finishes with its value."""
    plc = load()
    plc["VB240"], plc["VW242"], plc["VW244"] = 1, 700, 0
    plc["M3.0"], plc["M3.2"] = 1, 1
    plc.scan()
    plc["M3.0"], plc["M3.2"] = 0, 0
    assert (plc["M3.3"], plc["MB8"]) == (1, 8)
    for _ in range(200):
        if plc["M3.1"]:
            break
        plc.scan()
    assert (plc["M3.1"], plc["MB7"], plc["VW246"]) == (1, 0, 5)


@pytest.mark.parametrize("setup, error", [({"VB240": 3}, 19), ({"VB240": 32}, 6)])
def test_parameter_request_for_an_inactive_drive(setup, error):
    plc = load()
    plc["VW242"] = 700
    for k, v in setup.items():
        plc[k] = v
    assert request(plc, READS["W"]) == (1, error)


def test_db_ptr_must_be_16_bytes_of_v():
    """DB_Ptr pointing to M memory is Error 14."""
    plc = load(program=PROGRAM.replace("VW244, &VB400, M3.1", "VW244, &MB0, M3.1"))
    plc["VB240"], plc["VW242"] = 1, 700
    assert request(plc, READS["W"]) == (1, 14)


# ---------------------------------------------------------------- BCC
def test_bad_bcc_from_the_drive_is_error_2():
    """A response with a wrong BCC is Error 2; the next good one clears it."""
    plc = load()
    plc.run(0.1)
    plc.ports[0].peer.corrupt = 1
    errors = []
    for _ in range(100):
        plc.scan()
        errors.append(plc["MB6"])
    assert 2 in errors and errors[-1] == 0
    assert [e["error"] for e in master_of(plc).log].count(2) == 1


def test_parity_error_in_the_response_is_error_3():
    """A response character with a parity error: Error 3; the next good one clears it."""
    plc = load()
    plc.run(0.1)
    plc.ports[0].peer.bad_parity = 1
    plc.run(0.1)
    assert [e["error"] for e in master_of(plc).log].count(3) == 1 and plc["MB6"] == 0


GOOD = encode(Telegram(3, 0, 0, 0, 0xEB31, 0))


@pytest.mark.parametrize("data, bad, error, at_timeout", [
    (GOOD, (), 0, False),
    (encode(Telegram(1, 0, 0, 0, 0xEB31, 0)), (), 13, False),
    (GOOD[:1] + bytes((12,)) + GOOD[2:14], (), 12, False),
    (GOOD[:-1] + bytes((GOOD[-1] ^ 0x10,)), (), 2, False),
    (GOOD, (4,), 3, False),
    (b"\x03" + GOOD[1:], (), 11, True),
    (GOOD[:10], (), 10, True)])
def test_response_checks(data, bad, error, at_timeout):
    """Another device answers the telegram to drive 3 (no drive there) 5 ms
    after it: ADR 1 is Error 13, LGE 12 Error 12, a bad BCC 2, a parity
    error 3, at the last character; a first character not STX 11 and a
    short response 10, at the timeout."""
    from plcrt.engine.serial import Framing
    plc = load(active=0b1000)
    plc["VB212"] = 3
    first_end = 2292 + 18334
    plc.ports[0].receive(first_end + 5000, Framing(9600, 8, "even", "freeport"), data,
                         frozenset(bad))
    plc.run(0.1)
    entry = master_of(plc).log[0]
    assert entry["error"] == error
    assert entry["finished"] == (first_end + 50_000 if at_timeout else entry["last_char"])


def test_a_new_uss_init_drops_a_running_parameter_request_with_error_4():
    """USS_INIT Mode 0 then 1 while a read waits: the read ends with Error 4."""
    plc = load(active=0b1000)           # drive 3 is absent: the read never ends by itself
    plc["VB240"], plc["VW242"] = 3, 700
    plc["M3.0"] = 1
    plc.scan()
    plc["M3.0"], plc["VB200"] = 0, 0
    plc.scan()
    plc["VB200"] = 1
    plc.scan()
    assert (plc["M3.1"], plc["MB7"]) == (1, 4)


def test_drive_ignores_a_telegram_with_a_bad_bcc():
    """The drive does not answer a telegram with a bad BCC, nor one for an
    address it does not have; a good one it answers."""
    plc = load()
    peer = plc.ports[0].peer
    before = (len(peer.answers), peer.ignored)
    good = encode(Telegram(1, 0, 0, 0, 0x047E, 0))
    peer.take(plc.now_us, good[:-1] + bytes((good[-1] ^ 1,)))
    peer.take(plc.now_us, encode(Telegram(9, 0, 0, 0, 0x047E, 0)))
    assert (len(peer.answers), peer.ignored) == (before[0], before[1] + 2)
    peer.take(plc.now_us, good)
    assert len(peer.answers) == before[0] + 1


def test_drive_at_another_rate_never_answers():
    """Drives set to 19200 baud while the CPU sends at 9600: no answer, Error 1."""
    plc = load(plant(head="baud = 19200\n"))
    plc.run(0.2)
    assert plc["MB6"] == 1 and plc.ports[0].peer.ignored >= 2


# ---------------------------------------------------------------- plant keys
@pytest.mark.parametrize("text, words", [
    ("[port.0.uss]\n", "drive is missing"),
    (plant(drive_toml(address=32)), "address must be a USS address"),
    (plant(drive_toml(), drive_toml()), "already has address 1"),
    (plant(drive_toml(ramp_up_s=-1)), "ramp_up_s must be a number"),
    (plant(drive_toml(word="{ 700 = 70000 }")), "0..65535"),
    (plant(drive_toml(word="{ 700 = 1 }", dword="{ 700 = 1 }")), "already in another table"),
    (plant(drive_toml(spin=1)), "unknown key(s) spin"),
    (plant(drive_toml(model='"mm2"')), "model must be"),
    (plant(head="baud = 1000\n"), "baud must be one of"),
    ("[port.0.uss]\n[[port.0.uss.drive]]\naddress = 1\n[port.0.modbus_slave]\naddress = 1\n",
     "one device per port")])
def test_plant_keys_are_checked(text, words):
    with pytest.raises(PlcConfigError) as e:
        load_plant(text)
    assert words in str(e.value) and "port.0" in str(e.value)


# ---------------------------------------------------------------- the export
def sbr(name: str, number: int, params: list[tuple[str, str]], body: str = "") -> str:
    out = [f"SUBROUTINE_BLOCK {name}:SBR{number}", "TITLE=library block"]
    for section in ("IN", "OUT"):
        decls = [(i, t) for i, (s, t) in enumerate(params) if s == section]
        if decls:
            out.append(f"VAR_{'INPUT' if section == 'IN' else 'OUTPUT'}")
            out += [f"p{i}:{t};" for i, t in decls]
            out.append("END_VAR")
    out.append("BEGIN")
    if body:
        out += ["Network 1", *body.splitlines()]
    out.append("END_SUBROUTINE_BLOCK")
    return "\n".join(out) + "\n"


INIT_ITF = [("IN", "BYTE"), ("IN", "DWORD"), ("IN", "DWORD"), ("OUT", "BOOL"), ("OUT", "BYTE")]
CTRL_ITF = [("IN", "BOOL")] * 5 + [("IN", "BYTE"), ("IN", "BYTE"), ("IN", "REAL"),
                                   ("OUT", "BOOL"), ("OUT", "BYTE"), ("OUT", "WORD"),
                                   ("OUT", "REAL")] + [("OUT", "BOOL")] * 4
RPM_ITF = [("IN", "BOOL"), ("IN", "BYTE"), ("IN", "WORD"), ("IN", "WORD"), ("IN", "DWORD"),
           ("OUT", "BOOL"), ("OUT", "BYTE"), ("OUT", "WORD")]
EXPORT_OB1 = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     SM0.0
CALL   SBR1, VB200, VD204, VD208, M0.1, MB5
Network 2
LD     SM0.0
CALL   SBR2, M1.0, M1.1, M1.2, M1.3, M1.4, VB212, VB213, VD214, M2.0, MB6, VW218, VD220, M2.1, M2.2, M2.3, M2.4
Network 3
LD     SM0.0
CALL   SBR3, M3.0, VB240, VW242, VW244, &VB400, M3.1, MB7, VW246
END_ORGANIZATION_BLOCK
"""


def test_export_protected_blocks_run_the_library():
    """An export's USS_INIT / USS_CTRL / USS_RPM_W (interface, empty body)
    run the library, with one load warning naming plcrt's error number."""
    text = EXPORT_OB1 + sbr("USS_INIT", 1, INIT_ITF) + sbr("USS_CTRL", 2, CTRL_ITF) \
        + sbr("USS_RPM_W", 3, RPM_ITF)
    plc = load(program=text)
    warns = [d.message for d in plc.diagnostics]
    assert sum("USS protocol library" in w and "23" in w for w in warns) == 1
    plc["M1.0"] = 1
    plc.run(1.0)
    assert drive(plc).on and plc["M2.1"] == 1
    assert read(plc, "W", 700) == (1, 0, 5)


def test_export_block_with_another_interface_runs_its_own_code():
    """A USS_CTRL with another interface, or a USS_INIT with instructions, is
    the program's own subroutine, with a warning; the port stays PPI."""
    text = EXPORT_OB1 + sbr("USS_INIT", 1, INIT_ITF, body="LD SM0.0\n= M9.0") \
        + sbr("USS_CTRL", 2, CTRL_ITF[:7] + [("IN", "DWORD")] + CTRL_ITF[8:]) \
        + sbr("USS_RPM_W", 3, RPM_ITF)
    plc = load(program=text)
    own = [d.message for d in plc.diagnostics if "own subroutine runs" in d.message]
    assert len(own) == 2 and any("USS_CTRL" in w and "interface" in w for w in own)
    assert plc["SMB30"] == 0 and plc["M9.0"] == 1


# ---------------------------------------------------------------- the sample
def test_sample_program_runs_the_drive():
    """programs/uss: the drive reaches 50 % of 50 Hz (25 Hz) 5 s into its
    10 s ramp; the program reads P1082 (50.0) once."""
    from pathlib import Path
    root = Path(__file__).resolve().parents[2] / "programs" / "uss"
    plc = plcrt.load(root / "drive.awl", plant=root / "drive_plant.toml", scan_ms=10)
    plc.run(6.0)
    d = plc.ports[0].peer.drives[1]
    assert d.f == 25 and plc["VD100:REAL"] == 50.0 and plc["VD110:REAL"] == 50.0
    assert plc["MB3"] == 0


def test_a_fork_runs_on_with_its_own_master_and_drive():
    """A fork polls its own drive: stopping the twin leaves the original running."""
    plc = load()
    plc["M1.0"] = 1
    plc.run(1.0)
    twin = plc.fork()
    assert master_of(twin) is not master_of(plc)
    twin["M1.0"] = 0
    twin.run(5.0)
    plc.run(5.0)
    assert drive(twin).f == 0 and drive(plc).f == 25
