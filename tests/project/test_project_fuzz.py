"""A fuzz of the project-file reader: truncated, bit-flipped and
length-forged files, and zlib bombs, end in a PlcError (or load) within a
time and memory bound; never another exception, never a hang.

Mutants are drawn from a seeded generator, so a failure names the one
mutant to look at.  ``PLCRT_FUZZ_PROJECTS`` (default 25) says how many
mutants of each kind are tried per seed file, ``PLCRT_FUZZ_SEED`` draws
other ones: ``PLCRT_FUZZ_PROJECTS=20000 pytest tests/project/test_project_fuzz.py``
is the long run.  The seeds are the tests' own project files and, where
the shared corpus is present, its largest Micro/WIN V4, Micro/WIN V3 and
SMART V2 project (every project file of it when ``PLCRT_FUZZ_PROJECTS`` is
set).  Memory is traced
for every tenth mutant and for the bombs (tracing costs time).
"""

from __future__ import annotations

import functools
import os
import random
import struct
import sys
import time
import tracemalloc
import zlib
from pathlib import Path

import pytest

from plcrt.errors import PlcError
from plcrt.lang.stl import parse_program
from plcrt.project import read_project
from plcrt.project.container import MAX_STREAM

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from project_writer import container, project_bytes, stream  # noqa: E402
from wizard_writer import (hsc_counter, motion_axis, pid_loop, pid_record_v4,  # noqa: E402
                           position_record, pto_record, pwm_output, smart_lists, v4_tail)
from sysblock_writer import smart_block, v4_block  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CORPUS = ROOT.parent / "shared" / "corpus" / "mwp"
MUTANTS = int(os.environ.get("PLCRT_FUZZ_PROJECTS", "25"))
LONG = "PLCRT_FUZZ_PROJECTS" in os.environ
SEED = int(os.environ.get("PLCRT_FUZZ_SEED", "28"))
#: per mutant: wall-clock seconds and traced peak memory
TIME_BOUND = 5.0
MEMORY_BOUND = 3 * MAX_STREAM + (16 << 20)


def _seeds() -> dict[str, bytes]:
    from test_project_load import EVERY_CODE
    program = parse_program(EVERY_CODE, "x.awl")
    seeds = {"own.mwp": project_bytes(program, symbols=[("A", "I0.0", "a")],
                                      data=[("VW0", [1, 2], "c")]),
             "own.smart": project_bytes(program, smart=True),
             "own-system.mwp": project_bytes(program, system=v4_block(pulse_catch=(2,))),
             "own-system.smart": project_bytes(program, smart=True,
                                               system=smart_block(startup="RUN"))}
    env = os.environ.get("PLCRT_CORPUS")
    folder = Path(env) / "mwp" if env else CORPUS
    if folder.is_dir():
        kinds: set[bytes] = set()
        # one file of each version (the largest), every file in a long run
        files = sorted(folder.iterdir(), key=lambda f: (-f.stat().st_size, f.name))
        for f in files:
            data = f.read_bytes() if f.suffix in (".mwp", ".smart") else b""
            if data[:8] in (b"GJK\0R04.", b"GJK\0R03.", b"SH3\0R02.") and (
                    LONG or data[:8] not in kinds):
                kinds.add(data[:8])
                seeds[f"corpus~{f.name}"] = data
    return seeds


SEEDS = _seeds()


def _split(data: bytes) -> tuple[bytes, bytes]:
    """(header up to the length field, decompressed stream)."""
    at = {b"GJK\0R04.": 0x34, b"GJK\0R03.": 0x10, b"SH3\0R02.": 0x6C}[data[:8]]
    return data[:at], zlib.decompress(data[at + 4:])


def _check(data: bytes, name: str, traced: bool = True) -> None:
    """Reading ``data`` loads or raises a PlcError naming the file, within
    the bounds (memory only when ``traced``)."""
    if traced:
        tracemalloc.start()
    start = time.perf_counter()
    try:
        project = read_project(data, name)
        parse_program(project.awl, name)
    except PlcError as e:
        assert e.loc is None or e.loc.file == name
    finally:
        peak = tracemalloc.get_traced_memory()[1] if traced else 0
        tracemalloc.stop()
    elapsed = time.perf_counter() - start
    assert elapsed < TIME_BOUND, f"{name}: {elapsed:.1f} s"
    assert peak < MEMORY_BOUND, f"{name}: {peak >> 20} MiB"


def _mutants(kind: str, seed_name: str, rng: random.Random) -> list[tuple[str, bytes]]:
    data = SEEDS[seed_name]
    head, body = _split(data)
    out = []
    for k in range(MUTANTS):
        if kind == "truncated":           # the file or its stream cut anywhere
            if k % 2:
                mutant = data[:rng.randrange(len(data))]
            else:
                cut = body[:rng.randrange(len(body))]
                mutant = head + struct.pack("<I", len(cut)) + zlib.compress(cut)
        elif kind == "flipped":           # bits of the stream (the sections)
            raw = bytearray(body)
            for _ in range(rng.randint(1, 8)):
                raw[rng.randrange(len(raw))] ^= 1 << rng.randrange(8)
            mutant = head + struct.pack("<I", len(raw)) + zlib.compress(bytes(raw))
        elif kind == "forged":            # counts and lengths set to extremes
            raw = bytearray(body)
            for _ in range(rng.randint(1, 4)):
                at = rng.randrange(len(raw) - 4)
                width = rng.choice((1, 2, 4))
                raw[at:at + width] = rng.choice((b"\xff", b"\x00", b"\x7f")) * width
            mutant = head + struct.pack("<I", len(raw)) + zlib.compress(bytes(raw))
        else:                             # the header's length field forged
            forged = rng.choice((0, 1, len(body) - 1, len(body) + 1, MAX_STREAM,
                                 MAX_STREAM + 1, 0xFFFFFFFF, rng.randrange(1 << 32)))
            mutant = head + struct.pack("<I", forged) + data[len(head) + 4:]
        out.append((f"{seed_name}~{kind}{k}", mutant))
    return out


@pytest.mark.parametrize("seed_name", sorted(SEEDS))
@pytest.mark.parametrize("kind", ["truncated", "flipped", "forged", "length"])
def test_mutants_end_in_plc_errors(kind: str, seed_name: str) -> None:
    rng = random.Random(f"{SEED}/{kind}/{seed_name}")
    for k, (name, mutant) in enumerate(_mutants(kind, seed_name, rng)):
        _check(mutant, name, traced=k % 10 == 0)


def _wizard_seeds() -> list[tuple[str, bytes, int]]:
    """(name, stream, offset of its wizard sections) of projects with a
    record of each wizard the reader reads."""
    program = parse_program("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\n"
                            "= Q0.0\nEND_ORGANIZATION_BLOCK\n", "x.awl")
    v4 = v4_tail([pid_record_v4(), position_record(), pto_record(0),
                  pto_record(1, accel_ms=0)])
    smart = smart_lists([motion_axis(0, profiles=2)], [pid_loop(0, enabled=True)],
                        [hsc_counter(0, enabled=True, steps=2)],
                        [pwm_output(0), pwm_output(1, time_base=1), pwm_output(2)])
    out = []
    for name, tail, is_smart in (("wizards.mwp", v4, False), ("wizards.smart", smart, True)):
        body = stream(program, smart=is_smart, wizards=tail)
        out.append((name, body, len(body) - len(tail)))
    return out


@pytest.mark.parametrize("seed", _wizard_seeds(), ids=lambda s: s[0])
def test_mutated_wizard_records_end_in_plc_errors_or_valid_tables(seed: tuple) -> None:
    """Bits flipped and counts forged in the wizard sections only: the
    project loads (with a note where a section is not read) or raises a
    PlcError, and the plant tables it gives are always a valid plant file's."""
    from plcrt.devices.plant import load_plant

    name, body, start = seed
    smart = name.endswith(".smart")
    rng = random.Random(f"{SEED}/wizards/{name}")
    mapped = 0
    for k in range(MUTANTS * 8):
        raw = bytearray(body)
        for _ in range(rng.randint(1, 6)):
            at = rng.randrange(start, len(raw) - 4)
            if k % 2:
                raw[at] ^= 1 << rng.randrange(8)
            else:
                width = rng.choice((1, 2, 4, 8))
                raw[at:at + width] = rng.choice((b"\xff", b"\x00", b"\x7f", b"\x41")) * width
        mutant = container(bytes(raw[:len(body)]), smart=smart)
        _check(mutant, f"{name}~wizard{k}", traced=k % 10 == 0)
        try:
            project = read_project(mutant, name)
        except PlcError:
            continue
        if project.plant:
            mapped += 1
            load_plant(project.plant, name)        # raises if a table is not valid
    assert mapped > 0                              # the mutants did not all break the records


@functools.cache
def _bomb() -> bytes:
    """256 MiB of zeros, compressed (about 256 KB)."""
    bomb = zlib.compressobj(9)
    return b"".join(bomb.compress(bytes(1 << 20)) for _ in range(256)) + bomb.flush()


@pytest.mark.parametrize("declared", [MAX_STREAM + 1, 64, MAX_STREAM])
def test_zlib_bombs_are_bounded(declared: int) -> None:
    """A stream of 256 MiB of zeros is never inflated past what the header
    declares, nor past MAX_STREAM."""
    packed = _bomb()
    head = b"GJK\0R04.00" + bytes(26) + b"\xaa\xaa\0\0" * 4
    _check(head + struct.pack("<I", declared) + packed, "bomb.mwp")
    smart_head = b"SH3\0R02.04.00.00" + bytes(26 + 66)
    _check(smart_head + struct.pack("<I", declared) + packed, "bomb.smart")
    v3_head = b"GJK\0R03.10" + bytes(6)
    _check(v3_head + struct.pack("<I", declared) + packed, "bomb3.mwp")


def test_a_stream_longer_than_declared_is_refused() -> None:
    program = parse_program("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\n"
                            "= Q0.0\nEND_ORGANIZATION_BLOCK\n", "x.awl")
    data = project_bytes(program)
    head, body = _split(data)
    with pytest.raises(PlcError, match="not the 10 its header declares"):
        read_project(container(body, declared=10), "x.mwp")


# -- SMART V3 (.smartV3): the file, its zip and its members mutated; the zip
# and the members are encrypted again, so the mutants pass the tag


@functools.cache
def _v3_members() -> tuple[tuple[str, bytes], ...]:
    import smartv3_writer
    from test_project_load import EVERY_CODE
    program = parse_program(EVERY_CODE, "x.awl")
    return tuple(smartv3_writer.members(program, symbols=[("A", "I0.0", "a")],
                                        data=[("VW0", [1, 2], "c")]))


def _v3_mutant(kind: str, rng: random.Random) -> bytes:
    import smartv3_writer as v3
    entries = list(_v3_members())
    plain = v3.zip_bytes(entries)
    if kind == "file":                    # the file cut, or a bit of it flipped
        data = bytearray(v3.encrypt(plain))
        if rng.random() < 0.5:
            return bytes(data[:rng.randrange(len(data))])
        data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
        return bytes(data)
    if kind == "zip":                     # bits of the archive (directory, headers)
        raw = bytearray(plain)
        for _ in range(rng.randint(1, 8)):
            raw[rng.randrange(len(raw))] ^= 1 << rng.randrange(8)
        return v3.encrypt(bytes(raw))
    read = [i for i, (n, _) in enumerate(entries) if n.endswith((".poubin", ".dbbin", ".xml"))]
    at = rng.choice(read)
    raw = bytearray(entries[at][1])
    if kind == "member-truncated":
        raw = raw[:rng.randrange(len(raw))]
    elif kind == "member-flipped":
        for _ in range(rng.randint(1, 8)):
            raw[rng.randrange(len(raw))] ^= 1 << rng.randrange(8)
    else:                                 # counts and lengths set to extremes
        for _ in range(rng.randint(1, 4)):
            pos = rng.randrange(len(raw) - 4)
            width = rng.choice((1, 2, 4))
            raw[pos:pos + width] = rng.choice((b"\xff", b"\x00", b"\x7f")) * width
    entries[at] = (entries[at][0], bytes(raw))
    return v3.encrypt(v3.zip_bytes(entries))


@pytest.mark.parametrize("kind", ["file", "zip", "member-truncated", "member-flipped",
                                  "member-forged"])
def test_smartv3_mutants_end_in_plc_errors(kind: str) -> None:
    rng = random.Random(f"{SEED}/smartv3/{kind}")
    for k in range(MUTANTS):
        _check(_v3_mutant(kind, rng), f"own.smartV3~{kind}{k}", traced=k % 10 == 0)


def _system_span(data: bytes) -> tuple[int, int] | None:
    """(start, end) of the system block in the stream of ``data`` (up to
    the program block), or None."""
    from plcrt.project.container import open_container
    from plcrt.project.reader import _program_cursor
    from plcrt.project.r03 import find_v3_main
    from plcrt.project.sysblock import read_system_block, read_v3_system_block
    box = open_container(data, "seed")
    if box.format == "Micro/WIN V3":          # the six ranges, 120 bytes
        system = read_v3_system_block(box.stream, "seed", find_v3_main(box.stream))[0]
        return (system.offset, system.offset + 124) if system is not None else None
    end = _program_cursor(box).pos
    system = read_system_block(box.stream, "seed", box.format, end)[0]
    return (system.offset, end) if system is not None else None


SYSTEM_SEEDS = sorted(n for n in SEEDS if _system_span(SEEDS[n]) is not None)


@pytest.mark.parametrize("seed_name", SYSTEM_SEEDS)
def test_mutated_system_blocks_end_in_plc_errors(seed_name: str) -> None:
    """Bytes flipped and forged inside the system block only: the project
    reads with bounded settings, or a PlcError names the file."""
    data = SEEDS[seed_name]
    head, body = _split(data)
    lo, hi = _system_span(data)
    rng = random.Random(f"{SEED}/system/{seed_name}")
    for k in range(4 * MUTANTS):
        raw = bytearray(body)
        for _ in range(rng.randint(1, 6)):
            at = rng.randrange(lo, hi - 4)
            if k % 2:
                raw[at] ^= 1 << rng.randrange(8)
            else:
                width = rng.choice((1, 2, 4))
                raw[at:at + width] = rng.choice((b"\xff", b"\x00", b"\x7f", b"\x80")) * width
        name = f"{seed_name}~system{k}"
        mutant = head + struct.pack("<I", len(raw)) + zlib.compress(bytes(raw))
        _check(mutant, name, traced=k % 10 == 0)
        try:
            system = read_project(mutant, name).system
        except PlcError:
            continue
        if system is not None:                      # what is read is bounded
            for r in system.settings.ranges or ():
                assert r.area in "VMTC" and r.start <= 0xFFFF and r.count <= 0x10000
            assert all(0 <= a <= 126 for a in system.settings.addresses.values())
            assert system.settings.startup in (None, "RUN", "STOP", "LAST")
