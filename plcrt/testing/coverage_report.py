"""Network, rung-output and contact coverage across a test session.

The pytest plugin (:mod:`plcrt.testing.plugin`) turns the
:class:`~plcrt.engine.coverage.CoverageMap` of every instrumented harness
into a plain *entry* with :func:`entry_from_map`, merges the entries of one
program with :func:`merge_entry` (also across pytest-xdist workers, which is
why everything here is JSON-able data and no live object), and prints
:func:`report_lines` or writes :func:`to_json` at the end of the session.

An entry::

    {"networks": {"OB1/1": 0|1, ...},              # as CoverageMap.data()
     "outputs": {"OB1/1:12:1:=": bits, ...},        # bit 0 unpowered, bit 1 powered
     "contacts": {"OB1/1:10:1:LD": bits, ...},      # bit 0 seen open, bit 1 closed
     "meta": {"networks": {"OB1/1": [title, line]},
              "outputs": {"OB1/1:12:1:=": [network, mnemonic, operand, line]},
              "contacts": {"OB1/1:10:1:LD": [network, mnemonic, operand, line]}}}

This module does not run programs and imports neither the engine (only its
light coverage tables) nor pytest.
"""

from __future__ import annotations

from typing import Any

# only the probe tables and their merge, no engine: the xdist controller
# merges its workers' results with this module
from ..engine.coverage import PARTS, merge_data

Entry = dict[str, Any]
Store = dict[str, Entry]   #: program key (resolved path or paths) -> entry

#: output bits, as the probes of plcrt.engine.coverage set them
UNPOWERED, POWERED = 1, 2
#: contact bits
OPEN, CLOSED = 1, 2


def entry_from_map(cov: Any) -> Entry:
    """An entry from a live ``CoverageMap`` (what ran, and the names to show)."""
    data = cov.data()
    nets = {n.name: [n.title or "", _line(n.loc)] for n in cov.networks}

    def names(refs: Any) -> dict[str, list[Any]]:
        return {cov.output_key(o): [cov.networks[o.network].name, o.mnemonic, o.operand,
                                    _line(o.loc)] for o in refs}
    return {"networks": data["networks"], "outputs": data["outputs"],
            "contacts": data["contacts"],
            "meta": {"networks": nets, "outputs": names(cov.outputs),
                     "contacts": names(cov.contacts)}}


def merge_entry(store: Store, key: str, entry: Entry) -> None:
    """Union ``entry`` into ``store[key]`` (bits are OR-ed, names kept)."""
    old = store.get(key, {})
    merged = merge_data(old, entry)
    meta = {part: dict(old.get("meta", {}).get(part, {})) for part in PARTS}
    for part in PARTS:
        for k, v in entry.get("meta", {}).get(part, {}).items():
            meta[part].setdefault(k, v)
    merged["meta"] = meta
    store[key] = merged


def merge_store(store: Store, other: Store) -> None:
    """Merge every program of ``other`` (e.g. a worker's) into ``store``."""
    for key, entry in other.items():
        merge_entry(store, key, entry)


def summarize(entry: Entry) -> dict[str, Any]:
    """Counts and the findings of one program's entry."""
    nets = entry["networks"]
    meta_n = entry["meta"]["networks"]
    meta_o = entry["meta"]["outputs"]
    not_run = [n for n, hit in nets.items() if not hit]
    findings = []
    branches = 0
    for key, bits in entry["outputs"].items():
        branches += (bits & UNPOWERED) + (bits >> 1 & 1)
        network, mnemonic, operand, line = meta_o.get(key, [key.split(":")[0], "?", "", 0])
        if not nets.get(network, 0):
            continue        # its network never ran: listed once, as a network
        if bits == 0:
            what = "never reached"
        elif bits == UNPOWERED:
            what = "never true"
        elif bits == POWERED:
            what = "never false"
        else:
            continue
        findings.append({"network": network, "line": line, "mnemonic": mnemonic,
                         "operand": operand, "missing": what})
    conditions = 0
    contacts = entry.get("contacts", {})
    meta_c = entry["meta"].get("contacts", {})
    for key, bits in contacts.items():
        conditions += (bits & OPEN) + (bits >> 1 & 1)
        network, mnemonic, operand, line = meta_c.get(key, [key.split(":")[0], "?", "", 0])
        if not nets.get(network, 0) or bits == OPEN | CLOSED:
            continue
        what = {0: "never evaluated", OPEN: "never closed", CLOSED: "never open"}[bits]
        findings.append({"network": network, "line": line, "mnemonic": mnemonic,
                         "operand": operand, "missing": what})
    findings.sort(key=lambda f: (f["network"], f["line"]))
    run = len(nets) - len(not_run)
    return {
        "contacts_covered": conditions, "contacts_total": 2 * len(contacts),
        "networks_run": run, "networks_total": len(nets),
        "branches_covered": branches, "branches_total": 2 * len(entry["outputs"]),
        "networks_not_run": [{"network": n, "title": meta_n.get(n, ["", 0])[0],
                              "line": meta_n.get(n, ["", 0])[1]} for n in not_run],
        "outputs_missing": findings,
    }


def report_lines(store: Store) -> list[str]:
    """The terminal report: per program the counts, the networks that never
    ran and the outputs not reached both with and without power flow."""
    if not store:
        return ["no PLC program was run with coverage"]
    lines: list[str] = []
    tot = [0, 0, 0, 0, 0, 0]
    for key in sorted(store):
        s = summarize(store[key])
        tot[0] += s["networks_run"]
        tot[1] += s["networks_total"]
        tot[2] += s["branches_covered"]
        tot[3] += s["branches_total"]
        tot[4] += s["contacts_covered"]
        tot[5] += s["contacts_total"]
        lines.append(f"{key}: networks {_ratio(s['networks_run'], s['networks_total'])}, "
                     f"branches {_ratio(s['branches_covered'], s['branches_total'])}, "
                     f"contacts {_ratio(s['contacts_covered'], s['contacts_total'])}")
        for n in s["networks_not_run"]:
            title = f' "{n["title"]}"' if n["title"] else ""
            lines.append(f"  not run: {n['network']}{title} (line {n['line']})")
        for o in s["outputs_missing"]:
            what = f"{o['mnemonic']} {o['operand']}".rstrip()
            lines.append(f"  {o['network']} line {o['line']}: {what} {o['missing']}")
    if len(store) > 1:
        lines.append(f"TOTAL: networks {_ratio(tot[0], tot[1])}, "
                     f"branches {_ratio(tot[2], tot[3])}, contacts {_ratio(tot[4], tot[5])}")
    return lines


def to_json(store: Store) -> dict[str, Any]:
    """The JSON report: per program the raw bits (``data``, which
    :func:`plcrt.engine.coverage.merge_data` can merge with other runs),
    the names, and the summary."""
    programs = {}
    for key in sorted(store):
        e = store[key]
        programs[key] = {
            "data": {part: e.get(part, {}) for part in PARTS},
            "names": e["meta"],
            "summary": summarize(e),
        }
    return {"format": "plcrt-coverage", "version": 1, "programs": programs}


def _ratio(a: int, b: int) -> str:
    pct = 100.0 * a / b if b else 100.0
    return f"{a}/{b} ({pct:.1f} %)"


def _line(loc: Any) -> int:
    return int(getattr(loc, "line", 0) or 0)


__all__ = ["entry_from_map", "merge_entry", "merge_store", "report_lines", "summarize",
           "to_json"]
