"""Instruction family: program control and SCR.

END STOP WDR NOP JMP LBL FOR NEXT CALL CRET RET LSCR SCRT CSCRE SCRE.
(S7-200 System Manual, "Program control instructions" and "Sequence control
relay (SCR) instructions".)

Control flow is compiled, not interpreted: :mod:`plcrt.compiler.codegen`
splits POUs into pieces at labels, loops and SCR ends; these emitters make a
piece function ``return`` the index of the piece to continue at (``-1``
leaves the POU).  POUs without control flow pay nothing for it.
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..gen.limits import MAX_NESTING
from ..gen.operands import Addr, Const, Pointer
from ..gen.resolve import ResolveError, Resolver, check_role
from ..safetext import excerpt
from .registry import Role, insn

F = "control"

# Areas whose words live at a plain byte offset of one buffer.
_BYTE_AREAS = ("I", "Q", "M", "V", "SM", "S", "L")


def _info(g: Gen):
    return g.unit.current


def _piece(g: Gen):
    return g.unit.current_piece


@insn("END", family=F, summary="conditional end of the main program", flow="ret")
def _end(g: Gen) -> None:
    if _info(g).pou.kind != "OB":
        g.fail("END is only allowed in the main program (OB1)")
    _reject_in_scr(g, "END")
    with g.box():
        g.line("return -1")


@insn("CRET", family=F, summary="conditional return from a subroutine", flow="ret")
def _cret(g: Gen) -> None:
    if _info(g).pou.kind != "SBR":
        g.fail("CRET is only allowed in a subroutine")
    with g.box():
        g.line("return -1")


@insn("RET", family=F, summary="unconditional return from a subroutine", flow="ret")
def _ret(g: Gen) -> None:
    if _info(g).pou.kind != "SBR":
        g.fail("RET is only allowed in a subroutine")
    g.line("return -1")


@insn("MEND", family=F, summary="unconditional end of the main program", flow="ret")
def _mend(g: Gen) -> None:
    if _info(g).pou.kind != "OB":
        g.fail("MEND is only allowed in the main program (OB1)")
    g.line("return -1")


@insn("STOP", family=F, summary="go to STOP mode at the end of this scan")
def _stop(g: Gen) -> None:
    plc = g.cpu("request_stop", "stop")
    with g.box():
        g.line(f"{plc}()")


@insn("WDR", family=F, summary="retrigger the watchdog")
def _wdr(g: Gen) -> None:
    # The hard cap (WD[2]) still ends a loop that retriggers without end.
    with g.box():
        g.line(f"{g.use('WD')}[2] += {g.use('WD')}[0]")
        g.line(f"{g.use('WD')}[0] = 0")
        with g.block(f"if {g.use('WD')}[2] > 10 * {g.use('WD')}[1]:"):
            # the WDR's own instruction id: the fault names its line
            g.line(f"{g.use('_watchdog_wdr')}({int(g.insn_id)})")


@insn("LBL", Role.LABEL, family=F, summary="jump target", flow="label")
def _lbl(g: Gen, n: Const) -> None:
    pass


@insn("JMP", Role.LABEL, family=F, summary="jump to LBL n when the top is 1", flow="jump")
def _jmp(g: Gen, n: Const) -> None:
    info = _info(g)
    label = int(n.value)
    target = info.labels.get(label)
    if target is None:
        g.fail(f"jump to label {label}, which is not defined in {info.pou.ident} "
               f"(JMP and LBL must be in the same block)")
    here = _piece(g).index
    if info.scr_exit.get(here) != info.scr_exit.get(target):
        g.fail(f"jump to label {label} crosses an SCR segment boundary, which the "
               f"S7-200 does not allow")
    with g.box():
        g.line(f"return {int(target)}")


@insn("FOR", Role.W_W, Role.W_R, Role.W_R, family=F,
      summary="loop: INDX := INIT; repeat until INDX > FINAL", flow="for")
def _for(g: Gen, indx, init, final) -> None:
    _reject_in_scr(g, "FOR")
    info = _info(g)
    here = _piece(g).index
    body, exit_, _ = info.loops.get(here, (None, None, None))
    if body is None:
        g.fail("FOR without a matching NEXT", reported=True)   # by split_pieces
    with g.box():
        g.wr(indx, "W", g.rd(init, "W"))
        with g.block(f"if {g.rd(indx, 'W')} > {g.rd(final, 'W')}:"):
            g.line(f"return {int(exit_)}")
    with g.block("else:"):
        g.line(f"return {int(exit_)}")


@insn("NEXT", family=F, summary="end of a FOR loop", flow="next")
def _next(g: Gen) -> None:
    _reject_in_scr(g, "NEXT")
    info = _info(g)
    fp = info.next_of.get(_piece(g).index)
    if fp is None:
        g.fail("NEXT without a matching FOR", reported=True)
    body, _exit, for_insn = info.loops[fp]
    res = Resolver(g.unit.model, g.unit.symbols, g.unit.system_symbols, info.local_vars)
    indx = res.resolve(for_insn.operands[0], Role.W_W)
    final = res.resolve(for_insn.operands[2], Role.W_R)
    v = g.tmp("x")
    # INDX counts as an INT: past 32767 it wraps, as on the CPU (the
    # watchdog then ends the endless loop).  The increment works on the
    # unsigned pattern; direct byte-area words are read and written as two
    # bytes (big-endian), which is the fast path for the usual VW/MW index.
    if isinstance(indx, Addr) and indx.area in _BYTE_AREAS:
        buf, o = g.use(indx.area), indx.offset
        g.line(f"{v} = ({buf}[{o}] << 8 | {buf}[{o + 1}]) + 1 & 65535")
        g.line(f"{buf}[{o}] = {v} >> 8")
        g.line(f"{buf}[{o + 1}] = {v} & 255")
    else:
        g.line(f"{v} = {g.rd(indx, 'WU')} + 1 & 65535")
        g.wr(indx, "W", v)
    with g.block(f"if ({v} ^ 32768) - 32768 <= {g.rd(final, 'W')}:"):
        g.line(f"return {int(body)}")


# -- SCR -----------------------------------------------------------------
def _reject_in_scr(g: Gen, mnemonic: str) -> None:
    """FOR, NEXT and END cannot stand inside an SCR segment (System Manual,
    "Sequence control relay instructions", restrictions)."""
    info, piece = _info(g), _piece(g)
    if piece.index not in info.scr_exit:
        return
    # The piece that holds the LSCR may start with instructions of the
    # network before the LSCR: those are outside the segment.
    lscr = next((i for i in piece.insns if i.mnemonic == "LSCR"), None)
    if lscr is not None and g.loc is not None and \
            (g.loc.line, g.loc.column) < (lscr.loc.line, lscr.loc.column):
        return
    g.fail(f"{mnemonic} is not allowed inside an SCR segment")


@insn("LSCR", Role.SBIT, family=F, summary="start an SCR segment controlled by the S bit",
      flow="lscr")
def _lscr(g: Gen, bit: Addr) -> None:
    info = _info(g)
    if info.pou.kind == "INT":
        # System Manual, SCR: segments are usable in the main program and
        # in subroutines, not in interrupt routines.
        g.fail("SCR segments cannot be used in an interrupt routine")
    here = _piece(g).index
    exit_ = info.scr_exit.get(here)
    if exit_ is None:
        g.fail("LSCR without a matching SCRE", reported=True)
    info.scr_bit[here] = bit
    # The segment's S bit for SCRT in later pieces of the same segment.
    for p in info.scr_pieces.get(here, [here]):
        info.scr_bit[p] = bit
    g.push(g.rbit(bit))
    with g.block(f"if not {g.top}:"):
        # An inactive segment resets the TOF timers inside it (manual, TOF:
        # "a TOF in an inactive SCR segment is reset").
        for n in _tofs_in_segment(g, info, here):
            reset = g.cpu("timers.reset", "Treset")
            g.line(f"{reset}({int(n)})")
        g.line(f"return {int(exit_)}")


def _tofs_in_segment(g: Gen, info, start: int) -> list[int]:
    """Numbers of the TOF timers written inside the SCR segment at ``start``.

    The timer operand is resolved like any operand, so a TOF named by a
    symbol (``TOF Fan_Delay, +50``, common in SMART exports) is found too.
    Operands that do not resolve are reported by the TOF itself.
    """
    res = Resolver(g.unit.model, g.unit.symbols, g.unit.system_symbols, info.local_vars)
    found: list[int] = []
    for idx in info.scr_pieces.get(start, [start]):
        for ins in info.pieces[idx].insns:
            if ins.mnemonic == "TOF" and ins.operands:
                try:
                    t = res.resolve(ins.operands[0], Role.TIMER)
                except ResolveError:
                    continue
                if isinstance(t, Addr):
                    found.append(t.offset)
    return sorted(set(found))


@insn("SCRT", Role.SBIT, family=F, summary="transition: reset this segment's bit, set the target")
def _scrt(g: Gen, bit: Addr) -> None:
    info = _info(g)
    cur = info.scr_bit.get(_piece(g).index)
    if cur is None:
        g.fail("SCRT outside an SCR segment")
    with g.box():
        g.set_bit(cur, 0)
        g.set_bit(bit, 1)


@insn("CSCRE", family=F, summary="conditional end of the SCR segment", flow="cscre")
def _cscre(g: Gen) -> None:
    info = _info(g)
    exit_ = info.scr_exit.get(_piece(g).index)
    if exit_ is None:
        g.fail("CSCRE outside an SCR segment", reported=True)
    with g.box():
        g.line(f"return {int(exit_)}")


@insn("SCRE", family=F, summary="end of the SCR segment", flow="scre")
def _scre(g: Gen) -> None:
    pass


# -- CALL ------------------------------------------------------------------
_PARAM_ROLE = {
    ("IN", 0): Role.BIT_R, ("IN", 1): Role.B_R, ("IN", 2): Role.W_R, ("IN", 4): Role.D_R,
    ("OUT", 0): Role.BIT_W, ("OUT", 1): Role.B_W, ("OUT", 2): Role.W_W, ("OUT", 4): Role.D_W,
}
_KIND = {1: "B", 2: "WU", 4: "DU"}
#: types whose IN parameter also takes an address ``&VB100`` (a pointer):
#: Micro/WIN passes a pointer to a DWORD input (System Manual, "Pointers"
#: and "Subroutine parameters"), never to a DINT or REAL one
_POINTER_TYPES = ("DWORD",)


@insn("CALL", family=F, summary="call a subroutine with parameters", variadic=True,
      may_fail=True)
def _call(g: Gen, insn_ir, resolver, *_ops) -> None:
    # ENO is 0 only after a call refused for nesting (error 0008); a program
    # without the nesting check has no such call, and AENO changes nothing
    g.eno_valid = False
    if not insn_ir.operands:
        g.fail("CALL needs the subroutine to call")
    name = insn_ir.operands[0].text.split(":")[0]
    callee = g.unit.callee(name)
    if callee is None:
        hook = g.unit.hooks.get("library_call")
        if hook is not None and hook(g, insn_ir, resolver):
            return
        g.fail(f"no subroutine named '{excerpt(name)}' in the program")
    if callee.pou.kind != "SBR":
        g.fail(f"{callee.pou.ident} is not a subroutine")
    # a protected library subroutine of the export (an empty body): the
    # built-in block instead (PTOx_*, MBUS_*, ...; the engine installs the hook)
    hook = g.unit.hooks.get("protected_call")
    if hook is not None and hook(g, insn_ir, resolver, callee):
        return
    if callee.bad_vars:
        g.fail(f"{callee.pou.ident} ({excerpt(callee.pou.name)}) cannot be called: its "
               f"variable #{excerpt(callee.bad_vars[0])} has a type plcrt does not support "
               f"(see its declaration)")
    params = [v.decl for v in callee.local_vars.values() if v.decl.section != "TEMP"]
    actual = insn_ir.operands[1:]
    if len(actual) != len(params):
        g.fail(f"{callee.pou.ident} ({excerpt(callee.pou.name)}) takes {len(params)} parameter(s) "
               f"in the order IN, IN_OUT, OUT; the call passes {len(actual)}")
    copy_in: list[tuple] = []
    copy_out: list[tuple] = []
    for decl, op_ir in zip(params, actual):
        lv = callee.local_vars[decl.name]
        width = lv.addr.width or 0
        sections = ("IN",) if decl.section == "IN" else ("OUT",) if decl.section == "OUT" \
            else ("IN", "OUT")
        try:
            op = resolver.parse(op_ir.text)
            ops = {s: op if s == "IN" and isinstance(op, Pointer) and decl.section == "IN"
                   and decl.type.upper() in _POINTER_TYPES
                   else check_role(op, _PARAM_ROLE[(s, width)], op_ir.text, g.unit.model)
                   for s in sections}
        except ResolveError as e:
            g.fail(f"parameter #{excerpt(decl.name)} ({decl.type}, {decl.section}): {e}")
        if "IN" in ops:
            copy_in.append((lv.addr, ops["IN"], width))
        if "OUT" in ops:
            copy_out.append((lv.addr, ops["OUT"], width))
    l_bytes = g.unit.model.l_bytes
    if not g.unit.nest_check:
        with g.box():
            _call_body(g, callee, g.bind(bytearray(l_bytes), "Lc"), copy_in, copy_out)
        return
    # Run-time nesting check (System Manual, CALL: eight levels from the
    # main program; error 0008, SM4.3, ENO 0 on a deeper call).  WD[3] is
    # the number of subroutines active in this scan.
    wd = g.use("WD")
    with g.box():
        with g.block(f"if {wd}[3] >= {int(MAX_NESTING)}:"):
            refuse = g.cpu("_nesting_exceeded", "nest")
            g.line(f"{refuse}({int(g.insn_id)})")
            g.line("eno = 0")
        with g.block("else:"):
            if (_info(g).pou.ident, callee.pou.ident) in g.unit.recursive_sites:
                # a call site inside a cycle can be active at several levels
                # at once: one L buffer per level, as the CPU's L stack has
                lbufs = g.bind([bytearray(l_bytes) for _ in range(MAX_NESTING)], "Ls")
                lbuf = g.tmp("lb")
                g.line(f"{lbuf} = {lbufs}[{wd}[3]]")
            else:
                lbuf = g.bind(bytearray(l_bytes), "Lc")
            g.line(f"{wd}[3] += 1")
            _call_body(g, callee, lbuf, copy_in, copy_out, after=f"{wd}[3] -= 1")
            g.eno("1")


def _call_body(g: Gen, callee, lbuf: str, copy_in: list, copy_out: list,
               after: str = "") -> None:
    """Copy the inputs into the callee's L buffer ``lbuf``, call, copy the
    outputs back (``after`` runs right after the call returns)."""
    for dst, src, width in copy_in:
        if width == 0:
            m = 1 << dst.bit
            g.line(f"{lbuf}[{dst.offset}] = {lbuf}[{dst.offset}] & {~m & 0xFF} | "
                   f"{g.rbit(src)} << {dst.bit}")
        else:
            k = _KIND[width]
            _wr_local(g, lbuf, dst, k, g.rd(src, k))
    g.line(f"{callee.fname}({lbuf})")
    if after:
        g.line(after)
    for src, dst, width in copy_out:
        if width == 0:
            g.wbit(dst, f"({lbuf}[{src.offset}] >> {src.bit} & 1)")
        else:
            k = _KIND[width]
            codec = {"B": None, "WU": "_rH", "DU": "_rI"}[k]
            expr = f"{lbuf}[{src.offset}]" if codec is None else \
                f"{g.use(codec)}({lbuf}, {src.offset})[0]"
            g.wr(dst, k, expr)


def _wr_local(g: Gen, lbuf: str, dst: Addr, kind: str, expr: str) -> None:
    if kind == "B":
        g.line(f"{lbuf}[{dst.offset}] = ({expr}) & 255")
    elif kind == "WU":
        g.line(f"{g.use('_wH')}({lbuf}, {dst.offset}, ({expr}) & 65535)")
    else:
        g.line(f"{g.use('_wI')}({lbuf}, {dst.offset}, ({expr}) & 4294967295)")
