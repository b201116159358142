"""How each STL instruction appears in a ladder (LAD) network.

A table, derived from the mnemonic, that the ladder view and the coverage
instrumentation share.  It says what an instruction *looks like* in LAD and
how many power-flow inputs it takes from the logic stack; it says nothing
about what the instruction does (that is the registry's job).

Kinds:

``contact``
    ``LD``/``A``/``O`` families and the compare contacts: a contact that
    starts a branch (``load``), continues in series (``and``) or is placed
    in parallel (``or``).
``modifier``
    ``NOT``, ``EU``, ``ED``: an inline element on the wire.
``stack``
    ``ALD``, ``OLD``, ``LPS``, ``LRD``, ``LPP``, ``LDS``, ``AENO``: no
    picture of their own, they shape the rung.
``coil``
    an element at the right end of a rung (``=``, ``S``, ``R``, ``JMP``,
    ``SCRT``, ``CRET``, ``STOP``, ...), fed by one power input.
``box``
    a box with EN (``MOV_W``, ``TON``, ``CTU``, ``CALL`` ...); counters take
    two or three power inputs (System Manual, CTU/CTD/CTUD: count, reset
    and load inputs are separate rungs into the box).
``rail``
    an element connected straight to the left power rail, with no power
    input (``LBL``, ``LSCR``, ``SCRE``, ``NEXT``, ``RET``, ``MEND``).

For drawing, ``lad`` is the picture Micro/WIN uses: the inside of a contact
(``" "``, ``"/"``, ``"I"``, ``"/I"``, ``"==I"``, ``">=D"`` ...; compare
types B, I, D, R as in LAD, where STL's W is INT), the coil symbol with its
parentheses (``"( )"``, ``"(S)"``, ``"(JMP)"``), the modifier (``P``, ``N``,
``NOT``) or the box name (``MOV_W``, ``ADD_I``, ``TON``).  ``pins`` says
where the STL operands go, as space-separated items:

``@i``      operand i is written above the element (bit of a coil or contact
            rail box, timer or counter number, label number)
``_i``      operand i is written below (the count N of S/R)
``NAME=i``  input pin NAME on the left of the box, fed by operand i
``NAME>i``  output pin NAME on the right, written to operand i
``~NAME``   a power-flow input pin; a box without any has ``EN`` and passes
            power on through ``ENO``, one with them (timers, counters) has no
            ENO
an ``r`` after an index marks a REAL operand (for showing its value).

Micro/WIN draws STL's two-operand arithmetic ``+I IN1, OUT`` (OUT := OUT +
IN1) as ``ADD_I`` with IN1 = OUT and IN2 = the STL operand, which is how it
converts such a line back to LAD (System Manual, "Add, Subtract, Multiply
and Divide": LAD IN1 + IN2 = OUT, STL IN1 + OUT = OUT).  ``CALL`` gets its
pins from the called block's interface, not from this table.
"""

from __future__ import annotations

from typing import NamedTuple


class Shape(NamedTuple):
    """The LAD appearance of one mnemonic."""

    kind: str            #: contact, modifier, stack, coil, box, rail
    inputs: int = 0      #: power-flow inputs taken from the logic stack
    op: str = ""         #: contacts: load, and, or; stack: and, or, push, read,
    #:                       pop, copy (LDS), eno (AENO)
    negated: bool = False
    immediate: bool = False
    compare: str = ""    #: compare contacts: "B=", "W<>", "R>=", ...
    lad: str = ""        #: LAD picture: contact inside, coil symbol, box name
    pins: str = ""       #: where the operands are drawn (see module docstring)


#: stack instructions and what they do to the rung (the ``op`` of their shape)
_STACK = {"ALD": "and", "OLD": "or", "LPS": "push", "LRD": "read", "LPP": "pop",
          "LDS": "copy", "AENO": "eno"}
_MODIFIERS = {"NOT", "EU", "ED"}
_COILS = {"=", "=I", "S", "R", "SI", "RI", "JMP", "SCRT", "CSCRE", "CRET",
          "STOP", "WDR", "END", "ENI", "DISI", "CRETI"}
_RAIL = {"LBL", "LSCR", "SCRE", "NEXT", "RET", "MEND", "NOP", "RETI"}
#: power inputs of boxes with more than one (System Manual, counters)
_BOX_INPUTS = {"CTU": 2, "CTD": 2, "CTUD": 3}
_OPS = {"LD": "load", "A": "and", "O": "or"}
_COMPARE_TYPES = "BWDRS"
_RELATIONS = ("=", "<>", "<=", ">=", "<", ">")
#: compare contact insides as Micro/WIN draws them: ``LDW=`` is ``==I``
_LAD_TYPE = {"B": "B", "W": "I", "D": "D", "R": "R", "S": "S"}
_LAD_RELATION = {"=": "=="}
#: insides of bit contacts by (negated, immediate)
_LAD_BIT = {(False, False): " ", (True, False): "/", (False, True): "I", (True, True): "/I"}

_ARITH = "IN1=1 IN2=0 OUT>1"   # STL OUT := OUT op IN1, drawn as LAD (docstring)
_ARITH_R = "IN1=1r IN2=0r OUT>1r"
_UNARY = "IN=0 OUT>0"          # INCW, INVW, BCDI ...: one in-out operand
_SHIFT = "IN=0 N=1 OUT>0"
_MOVE = "IN=0 OUT>1"
_BLOCK = "IN=0 N=2 OUT>1"

#: LAD picture and operand pins of coils, modifiers, rail elements and
#: boxes, after the S7-200 System Manual's LAD boxes.  Mnemonics missing here
#: (instructions plcrt does not run yet) are drawn as a box named after the
#: mnemonic with its operands as unnamed inputs.
_LAD: dict[str, tuple[str, str]] = {
    # coils (System Manual, "Bit logic", "Program control", "SCR")
    "=": ("( )", "@0"), "=I": ("(I)", "@0"),
    "S": ("(S)", "@0 _1"), "R": ("(R)", "@0 _1"),
    "SI": ("(SI)", "@0 _1"), "RI": ("(RI)", "@0 _1"),
    "JMP": ("(JMP)", "@0"), "SCRT": ("(SCRT)", "@0"), "CSCRE": ("(SCRE)", ""),
    "CRET": ("(RET)", ""), "STOP": ("(STOP)", ""), "WDR": ("(WDR)", ""),
    "END": ("(END)", ""),
    # interrupts (System Manual, "Interrupt instructions")
    "ENI": ("(ENI)", ""), "DISI": ("(DISI)", ""), "CRETI": ("(RETI)", ""),
    "RETI": ("(RETI)", ""),
    "ATCH": ("ATCH", "INT=0 EVNT=1"), "DTCH": ("DTCH", "EVNT=0"),
    "CEVNT": ("CLR_EVNT", "EVNT=0"),
    # high-speed outputs (System Manual, PLS: the box's Q0.X input)
    "PLS": ("PLS", "Q0_X=0"),
    "HDEF": ("HDEF", "HSC=0 MODE=1"), "HSC": ("HSC", "N=0"),
    # the PID loop (System Manual, PID: the table and the loop number)
    "PID": ("PID", "TBL=0 LOOP=1"),
    # communications (System Manual, XMT/RCV/NETR/NETW; SMART manual, GET/PUT)
    "XMT": ("XMT", "TBL=0 PORT=1"), "RCV": ("RCV", "TBL=0 PORT=1"),
    "NETR": ("NETR", "TABLE=0 PORT=1"), "NETW": ("NETW", "TABLE=0 PORT=1"),
    "GET": ("GET", "TABLE=0"), "PUT": ("PUT", "TABLE=0"),
    # modifiers: contacts without an operand
    "NOT": ("NOT", ""), "EU": ("P", ""), "ED": ("N", ""),
    # rail elements: coils, or boxes (a name without parentheses)
    "SCRE": ("(SCRE)", ""), "NEXT": ("(NEXT)", ""), "RET": ("(RET)", ""),
    "MEND": ("(END)", ""), "LBL": ("LBL", "@0"), "LSCR": ("SCR", "@0"),
    "NOP": ("NOP", "@0"),
    # timers and counters: the number above the box, power inputs on pins
    "TON": ("TON", "@0 ~IN PT=1"), "TOF": ("TOF", "@0 ~IN PT=1"),
    "TONR": ("TONR", "@0 ~IN PT=1"),
    "CTU": ("CTU", "@0 ~CU ~R PV=1"), "CTD": ("CTD", "@0 ~CD ~LD PV=1"),
    "CTUD": ("CTUD", "@0 ~CU ~CD ~R PV=1"),
    # moves
    "MOVB": ("MOV_B", _MOVE), "MOVW": ("MOV_W", _MOVE), "MOVD": ("MOV_DW", _MOVE),
    "MOVR": ("MOV_R", "IN=0r OUT>1r"), "BIR": ("MOV_BIR", _MOVE), "BIW": ("MOV_BIW", _MOVE),
    "BMB": ("BLKMOV_B", _BLOCK), "BMW": ("BLKMOV_W", _BLOCK), "BMD": ("BLKMOV_D", _BLOCK),
    "FILL": ("FILL_N", _BLOCK), "SWAP": ("SWAP", "IN=0"),
    # integer arithmetic
    "+I": ("ADD_I", _ARITH), "-I": ("SUB_I", _ARITH), "*I": ("MUL_I", _ARITH),
    "/I": ("DIV_I", _ARITH), "+D": ("ADD_DI", _ARITH), "-D": ("SUB_DI", _ARITH),
    "*D": ("MUL_DI", _ARITH), "/D": ("DIV_DI", _ARITH), "MUL": ("MUL", _ARITH),
    "DIV": ("DIV", _ARITH),
    "INCB": ("INC_B", _UNARY), "INCW": ("INC_W", _UNARY), "INCD": ("INC_DW", _UNARY),
    "DECB": ("DEC_B", _UNARY), "DECW": ("DEC_W", _UNARY), "DECD": ("DEC_DW", _UNARY),
    # real arithmetic and functions
    "+R": ("ADD_R", _ARITH_R), "-R": ("SUB_R", _ARITH_R), "*R": ("MUL_R", _ARITH_R),
    "/R": ("DIV_R", _ARITH_R), "SQRT": ("SQRT", "IN=0r OUT>1r"),
    "SIN": ("SIN", "IN=0r OUT>1r"), "COS": ("COS", "IN=0r OUT>1r"),
    "TAN": ("TAN", "IN=0r OUT>1r"), "LN": ("LN", "IN=0r OUT>1r"),
    "EXP": ("EXP", "IN=0r OUT>1r"),
    # word logic, shifts and rotations
    "ANDB": ("WAND_B", _ARITH), "ANDW": ("WAND_W", _ARITH), "ANDD": ("WAND_DW", _ARITH),
    "ORB": ("WOR_B", _ARITH), "ORW": ("WOR_W", _ARITH), "ORD": ("WOR_DW", _ARITH),
    "XORB": ("WXOR_B", _ARITH), "XORW": ("WXOR_W", _ARITH), "XORD": ("WXOR_DW", _ARITH),
    "INVB": ("INV_B", _UNARY), "INVW": ("INV_W", _UNARY), "INVD": ("INV_DW", _UNARY),
    "SLB": ("SHL_B", _SHIFT), "SLW": ("SHL_W", _SHIFT), "SLD": ("SHL_DW", _SHIFT),
    "SRB": ("SHR_B", _SHIFT), "SRW": ("SHR_W", _SHIFT), "SRD": ("SHR_DW", _SHIFT),
    "RLB": ("ROL_B", _SHIFT), "RLW": ("ROL_W", _SHIFT), "RLD": ("ROL_DW", _SHIFT),
    "RRB": ("ROR_B", _SHIFT), "RRW": ("ROR_W", _SHIFT), "RRD": ("ROR_DW", _SHIFT),
    "SHRB": ("SHRB", "DATA=0 S_BIT=1 N=2"),
    # conversions
    "BTI": ("B_I", _MOVE), "ITB": ("I_B", _MOVE), "ITD": ("I_DI", _MOVE),
    "DTI": ("DI_I", _MOVE), "DTR": ("DI_R", "IN=0 OUT>1r"), "ROUND": ("ROUND", "IN=0r OUT>1"),
    "TRUNC": ("TRUNC", "IN=0r OUT>1"), "BCDI": ("BCD_I", _UNARY), "IBCD": ("I_BCD", _UNARY),
    "DECO": ("DECO", _MOVE), "ENCO": ("ENCO", _MOVE), "SEG": ("SEG", _MOVE),
    # strings (System Manual, "String instructions", "String conversion")
    "SLEN": ("STR_LEN", _MOVE), "SCPY": ("STR_CPY", _MOVE), "SCAT": ("STR_CAT", _MOVE),
    "SSCPY": ("SSTR_CPY", "IN=0 INDX=1 N=2 OUT>3"),
    "SFND": ("STR_FIND", "IN1=0 IN2=1 OUT>2"), "CFND": ("CHR_FIND", "IN1=0 IN2=1 OUT>2"),
    "ITS": ("I_S", "IN=0 FMT=2 OUT>1"), "DTS": ("DI_S", "IN=0 FMT=2 OUT>1"),
    "RTS": ("R_S", "IN=0r FMT=2 OUT>1"),
    "STI": ("S_I", "IN=0 INDX=1 OUT>2"), "STD": ("S_DI", "IN=0 INDX=1 OUT>2"),
    "STR": ("S_R", "IN=0 INDX=1 OUT>2r"),
    # ASCII conversions (System Manual, "Conversion instructions")
    "ITA": ("I_A", "IN=0 FMT=2 OUT>1"), "DTA": ("DI_A", "IN=0 FMT=2 OUT>1"),
    "RTA": ("R_A", "IN=0r FMT=2 OUT>1"),
    "ATH": ("ATH", "IN=0 LEN=2 OUT>1"), "HTA": ("HTA", "IN=0 LEN=2 OUT>1"),
    # tables (System Manual, "Table instructions"): FND's CMD (1 =, 2 <>,
    # 3 <, 4 >) is written in the box, see FIND_CMD
    "ATT": ("AD_T_TBL", "DATA=0 TBL=1"),
    "FIFO": ("FIFO", "TBL=0 DATA>1"), "LIFO": ("LIFO", "TBL=0 DATA>1"),
    "FND=": ("TBL_FIND", "TBL=0 PTN=1 INDX=2"), "FND<>": ("TBL_FIND", "TBL=0 PTN=1 INDX=2"),
    "FND<": ("TBL_FIND", "TBL=0 PTN=1 INDX=2"), "FND>": ("TBL_FIND", "TBL=0 PTN=1 INDX=2"),
    # clock (System Manual, "Clock instructions"; SMART: the extended ones)
    "TODR": ("READ_RTC", "T>0"), "TODW": ("SET_RTC", "T=0"),
    "TODRX": ("READ_RTCX", "T>0"), "TODWX": ("SET_RTCX", "T=0"),
    # SMART: interval timers, diagnostic LED; port addresses (communication)
    "BITIM": ("BGN_ITIME", "OUT>0"), "CITIM": ("CAL_ITIME", "IN=0 OUT>1"),
    "DLED": ("DIAG_LED", "IN=0"),
    "GPA": ("GET_ADDR", "ADDR>0 PORT=1"), "SPA": ("SET_ADDR", "ADDR=0 PORT=1"),
    # program control
    "FOR": ("FOR", "INDX=0 INIT=1 FINAL=2"), "CALL": ("CALL", ""),
}

#: the CMD input of Micro/WIN's TBL_FIND box for each STL FND mnemonic
FIND_CMD = {"FND=": 1, "FND<>": 2, "FND<": 3, "FND>": 4}


def _contact(mnemonic: str) -> Shape | None:
    for prefix in ("LD", "A", "O"):
        if not mnemonic.startswith(prefix):
            continue
        rest = mnemonic[len(prefix):]
        if rest in ("", "N", "I", "NI"):
            neg, imm = "N" in rest, "I" in rest
            return Shape("contact", 0, _OPS[prefix], neg, imm,
                         lad=_LAD_BIT[neg, imm], pins="@0")
        if len(rest) >= 2 and rest[0] in _COMPARE_TYPES and rest[1:] in _RELATIONS:
            rel = rest[1:]
            lad = _LAD_RELATION.get(rel, rel) + _LAD_TYPE[rest[0]]
            return Shape("contact", 0, _OPS[prefix], compare=rest, lad=lad,
                         pins="@0" + "r" * (rest[0] == "R") + " _1" + "r" * (rest[0] == "R"))
    return None


def shape(mnemonic: str) -> Shape:
    """The LAD shape of an (upper-case) mnemonic; unknown ones are boxes."""
    m = mnemonic.upper()
    lad, pins = _LAD.get(m, ("", ""))
    if m in _STACK:
        return Shape("stack", op=_STACK[m])
    if m in _MODIFIERS:
        return Shape("modifier", 1, lad=lad)
    if m in _COILS:
        return Shape("coil", 1, lad=lad, pins=pins)
    if m in _RAIL:
        return Shape("rail", lad=lad, pins=pins)
    c = _contact(m)
    if c is not None:
        return c
    return Shape("box", _BOX_INPUTS.get(m, 1), lad=lad or m, pins=pins)


__all__ = ["FIND_CMD", "Shape", "shape"]
