"""The Python backend keeps bits in locals within a run of bit logic.

Rules pinned here (plcrt/compiler/bitcache.py, docs/architecture.md "Bits
kept in locals"): a bit read again is read from the image once per
function; a written bit is stored once where the run ends; any other
instruction (a box, a CALL, ENI, an immediate output ...) sees the image as
the straight code leaves it, and a bit kept in a local is read again after
it; instrumented builds keep no bits in locals.
"""

from __future__ import annotations

import pytest

import plcrt


def _ob1(*networks: str, extra: str = "") -> str:
    body = "".join(f"Network {i}\n{n.strip()}\n" for i, n in enumerate(networks, 1))
    return f"ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\n{body}END_ORGANIZATION_BLOCK\n{extra}"


def _sbr0(*networks: str) -> str:
    body = "".join(f"Network {i}\n{n.strip()}\n" for i, n in enumerate(networks, 1))
    return f"SUBROUTINE_BLOCK SBR_0:SBR0\nBEGIN\n{body}END_SUBROUTINE_BLOCK\n"


def _backends() -> list[str]:
    try:
        import llvmlite  # noqa: F401
    except ImportError:
        return ["python"]
    return ["python", "native"]


def test_a_bit_read_in_several_networks_is_read_from_the_image_once() -> None:
    text = _ob1("LD M0.3\n= Q0.0", "LDN M0.3\n= Q0.1", "LD I0.0\nA M0.3\n= Q0.2")
    plc = plcrt.load(text, backend="python")
    assert plc.source.count("M[0] >> 3 & 1") == 1
    plc["M0.3"], plc["I0.0"] = 1, 1
    plc.scan()
    assert (plc["Q0.0"], plc["Q0.1"], plc["Q0.2"]) == (1, 0, 1)


def test_bits_written_in_a_run_are_stored_once_per_byte() -> None:
    # Q0.0, Q0.1, Q0.5 from three networks: one store of QB0 (the other
    # bits of QB0 are kept), and a later network reads the new Q0.0
    text = _ob1("LD I0.0\n= Q0.0", "LDN I0.0\n= Q0.1", "LD I0.1\n= Q0.5",
                "LD Q0.0\nA Q0.5\n= M1.0")
    plc = plcrt.load(text, backend="python")
    assert plc.source.count("Q[0] = ") == 1
    plc["QB0"] = 0b1000_0000          # Q0.7 is no output of the program
    plc["I0.0"], plc["I0.1"] = 1, 1
    plc.scan()
    assert plc["QB0"] == 0b1010_0001 and plc["M1.0"] == 1
    plc["I0.0"] = 0
    plc.scan()
    assert plc["QB0"] == 0b1010_0010 and plc["M1.0"] == 0


@pytest.mark.parametrize("backend", _backends())
def test_a_box_after_a_coil_sees_the_bit_written(backend: str) -> None:
    # = M0.1 in a run, then MOVB reads MB0 in the same network: the run
    # ends before the box, the bit is in the image
    text = _ob1("LD I0.0\n= M0.1\nLD M0.1\nMOVB MB0, VB10\nLD M0.1\n= Q0.0")
    plc = plcrt.load(text, backend=backend)
    plc["I0.0"] = 1
    plc.scan()
    assert plc["VB10"] == 2 and plc["Q0.0"] == 1


@pytest.mark.parametrize("backend", _backends())
def test_a_bit_kept_in_a_local_is_read_again_after_a_call(backend: str) -> None:
    # OB1 reads M0.0 before and after CALL SBR0, which sets it, and writes
    # M0.2 before the call, which the subroutine reads
    text = _ob1("LD M0.0\n= Q0.0\nLD I0.0\n= M0.2", "LD SM0.0\nCALL SBR_0",
                "LD M0.0\n= Q0.1\nLD M0.0\n= Q0.2",
                extra=_sbr0("LD SM0.0\nS M0.0, 1", "LD M0.2\n= Q1.0"))
    plc = plcrt.load(text, backend=backend)
    plc["I0.0"] = 1
    plc.scan()
    assert (plc["Q0.0"], plc["Q0.1"], plc["Q0.2"], plc["Q1.0"]) == (0, 1, 1, 1)


@pytest.mark.parametrize("backend", _backends())
def test_a_bit_kept_in_a_local_is_read_again_after_an_interrupt_point(backend: str) -> None:
    # INT0 (I0.0 rising, event 0) sets M0.1; interrupts are off (DISI at
    # the end of every scan), so the occurrence waits for ENI in network 3:
    # M0.1 is 0 before the ENI and 1 after it, in the same scan
    int0 = "INTERRUPT_BLOCK INT_0:INT0\nBEGIN\nNetwork 1\nLD SM0.0\nS M0.1, 1\nEND_INTERRUPT_BLOCK\n"
    text = _ob1("LD SM0.1\nATCH INT_0, 0", "LD M0.1\n= Q0.0\nLD M0.1\n= Q0.2",
                "ENI", "LD M0.1\n= Q0.1\nLD M0.1\n= Q0.3", "DISI", extra=int0)
    plc = plcrt.load(text, backend=backend)
    plc.scan()
    plc["I0.0"] = 1
    plc.scan()
    assert (plc["Q0.0"], plc["Q0.2"], plc["Q0.1"], plc["Q0.3"]) == (0, 0, 1, 1)


def test_an_instrumented_build_keeps_no_bits_in_locals() -> None:
    # a breakpoint's handler and the coverage probes see the image between
    # any two networks
    text = _ob1("LD M0.3\n= Q0.0", "LD M0.3\n= Q0.1")
    assert "bM0_3" in plcrt.load(text, backend="python").source
    assert "bM0_3" not in plcrt.load(text, backend="python", instrument=True).source


def test_a_run_that_ends_with_the_block_stores_its_bits_before_the_next_block() -> None:
    # SBR0's last network writes Q0.0 in a run; OB1 reads it after the CALL
    text = _ob1("LD SM0.0\nCALL SBR_0", "LD Q0.0\n= Q0.1",
                extra=_sbr0("LD I0.0\n= Q0.0"))
    plc = plcrt.load(text, backend="python")
    plc["I0.0"] = 1
    plc.scan()
    assert (plc["Q0.0"], plc["Q0.1"]) == (1, 1)
