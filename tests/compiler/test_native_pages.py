"""After a large compile the native backend hands the llvmlite library's
resident code pages back (plcrt/compiler/native/pages.py): only clean
read-only mappings of the library, and the machine code keeps running.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from plcrt.compiler.native.pages import _clean_mappings

SMAPS = """\
7f0000000000-7f0000100000 r--p 00000000 fe:01 42 /venv/llvmlite/binding/libllvmlite.so
Size:               1024 kB
Rss:                1024 kB
Anonymous:             0 kB
7f0000100000-7f0000900000 r-xp 00100000 fe:01 42 /venv/llvmlite/binding/libllvmlite.so
Size:               8192 kB
Anonymous:             0 kB
7f0000900000-7f0000a00000 r--p 00900000 fe:01 42 /venv/llvmlite/binding/libllvmlite.so
Size:               1024 kB
Anonymous:           512 kB
7f0000a00000-7f0000a10000 rw-p 00a00000 fe:01 42 /venv/llvmlite/binding/libllvmlite.so
Size:                 64 kB
Anonymous:             0 kB
7f0000b00000-7f0000c00000 r-xp 00000000 fe:01 43 /usr/lib/libc.so.6
Size:               1024 kB
Anonymous:             0 kB
7f0000c00000-7f0000d00000 rw-p 00000000 00:00 0
Size:               1024 kB
Anonymous:          1024 kB
"""


def test_only_the_librarys_clean_read_only_mappings_are_chosen() -> None:
    # the relocated (written) read-only part, the writable data and other
    # libraries' or anonymous mappings are never handed back
    assert _clean_mappings(SMAPS, "libllvmlite") == [
        (0x7f0000000000, 0x7f0000100000), (0x7f0000100000, 0x7f0000900000)]
    assert _clean_mappings(SMAPS, "libnothing") == []


CHILD = """
import sys
from pathlib import Path
import plcrt
from plcrt.compiler.native.pages import release_library_pages

def rss_file():
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("RssFile:"):
            return int(line.split()[1])

text = sys.argv[1]
nat = plcrt.load(text, backend="native")
before = rss_file()
released = release_library_pages()
after = rss_file()
py = plcrt.load(text, backend="python")
for plc in (nat, py):
    plc.mem.areas["V"][:64] = bytes(range(7, 71))
for k in range(20):
    for plc in (nat, py):
        plc.mem.areas["PI"][0] = k % 4
        plc.scan()
same = all(bytes(nat.mem.areas[a]) == bytes(py.mem.areas[a]) for a in ("Q", "M", "V", "TV"))
again = plcrt.load(sys.argv[2], backend="native")     # another program: LLVM runs again
again.scan(3)
print(released, before, after, same, nat.backend["name"], again.backend["name"])
"""


def test_released_pages_come_back_and_the_machine_code_runs(tmp_path) -> None:
    """In a fresh process (the library's pages are its own): the release
    lowers the mapped file pages, the machine code made before it still
    gives the Python build's memory, and LLVM compiles again after it."""
    pytest.importorskip("llvmlite")
    if not Path("/proc/self/smaps").exists():
        pytest.skip("no /proc/self/smaps: the release does nothing here")
    body = "".join(f"Network {i}\nLD     I0.{i % 4}\nMOVB   VB{i % 60}, MB{i % 30}\n"
                   f"+I     VW{2 * (i % 20)}, VW{40 + 2 * (i % 10)}\n=      Q0.{i % 8}\n"
                   for i in range(1, 200))
    text = f"ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\n{body}END_ORGANIZATION_BLOCK\n"
    other = text.replace("Q0.", "M9.")
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(CHILD), text, other],
                       capture_output=True, text=True, check=False, timeout=300,
                       env={"PLCRT_CACHE_DIR": str(tmp_path), "PATH": "/usr/bin:/bin"})
    assert r.returncode == 0, r.stderr[-2000:]
    released, before, after, same, name, again = r.stdout.split()
    assert int(released) > 0
    assert int(after) < int(before)
    assert same == "True" and name == "native" and again == "native"
