"""With the native backend a block's pieces are planned and emitted a
window at a time (plcrt/compiler/codegen.py, NATIVE_WINDOW): never more
than a window's resolved instructions at once, and the same IR, the same
generated Python and the same bindings whatever the window.
"""

from __future__ import annotations

import zlib

import pytest

import plcrt
from plcrt.compiler import codegen
from plcrt.compiler import native
from plcrt.compiler.cache import programs

pytest.importorskip("llvmlite")

SHAPES = ("LD     I0.{a}\nA      M{m}.{b}\n=      Q0.{b}\n",
          "LD     I0.{a}\nMOVW   VW{w}, VW{v}\n+I     +3, VW{v}\n",
          "LD     I0.{a}\nEU\nINCB   MB{m}\n",
          "LD     I0.{a}\nCALL   SBR_0\n",                      # stays Python
          "LDW>=  VW{w}, +100\nTON    T{t}, +5\n",
          "LD     T{t}\nR      T{t}, 1\n")


def _program(networks: int, jump: bool) -> str:
    body = [SHAPES[i % len(SHAPES)].format(a=i % 8, b=(i * 3) % 8, m=i % 20, w=2 * (i % 30),
                                           v=100 + 2 * (i % 10), t=37 + i % 10)
            for i in range(networks)]
    if jump:      # a block with a jump: each lowered piece is its own segment
        body[2] += "LD     I1.0\nJMP    4\n"
        body[networks - 3] = "LBL    4\n" + body[networks - 3]
    ob1 = "".join(f"Network {i}\n{n}" for i, n in enumerate(body, 1))
    return (f"ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\n{ob1}END_ORGANIZATION_BLOCK\n"
            "SUBROUTINE_BLOCK SBR_0:SBR0\nBEGIN\nNetwork 1\nLD     I0.1\nINCW   VW300\n"
            "END_SUBROUTINE_BLOCK\n")


def _build(text: str, window: int, monkeypatch) -> plcrt.Plc:
    monkeypatch.setattr(codegen, "NATIVE_WINDOW", window)
    programs.clear()
    return plcrt.load(text, backend="native")


@pytest.mark.parametrize("jump", [False, True])
def test_any_window_gives_the_same_build(monkeypatch, tmp_path, jump) -> None:
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path))
    text = _program(40, jump)
    seen: list[int] = []
    plan = native.plan_pou

    def counting(plan_, block, flow, pieces, carry=None):  # noqa: ANN001, ANN202
        seen.append(len(pieces))
        return plan(plan_, block, flow, pieces, carry)

    monkeypatch.setattr(native, "plan_pou", counting)
    builds = {}
    for window in (1, 7, 10**6):
        seen.clear()
        plc = _build(text, window, monkeypatch)
        assert max(seen) <= window and sum(seen) >= 40
        e = plc.compiled
        builds[window] = (b"".join(zlib.decompress(m) for m in e.native_ir),
                          zlib.decompress(e.source), sorted(e.bindings),
                          plc.backend["segments"], plc.backend["pieces"], plc.backend["python"])
    assert builds[1] == builds[7] == builds[10**6]
    segments, pieces = builds[1][3], builds[1][4]
    assert pieces > 20 and (segments == pieces if jump else segments < pieces)
    # and it runs as the Python backend does
    programs.clear()
    py = plcrt.load(text, backend="python")
    for k in range(30):
        for p in (plc, py):
            p.mem.areas["PI"][0] = (k * 37) & 0xFF
            p.mem.areas["PI"][1] = k & 1
            p.scan()
        for area in ("Q", "M", "V", "TV", "TB"):
            assert bytes(plc.mem.areas[area]) == bytes(py.mem.areas[area]), (k, area)
    programs.clear()
