"""The ``plcrt cia402`` command: tools for the simulated CiA 402 drives.

``plcrt cia402 eds MODEL [-o FILE]`` writes the EDS file of a drive model
(generated from ``library/cia402/MODEL.toml``); ``plcrt cia402 models`` lists
the models.  This module only parses arguments and prints; the work is done
by :mod:`.canopen_od`.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ...errors import PlcConfigError


def add_parser(subparsers: Any) -> None:
    """Add the ``cia402`` command (with ``eds`` and ``models``) to the
    ``plcrt`` parser's subcommands."""
    p = subparsers.add_parser(
        "cia402", help="CiA 402 drive models: EDS files and model list",
        description="Tools for plcrt's simulated CiA 402 bus drives.")
    sub = p.add_subparsers(dest="cia402_command", metavar="ACTION", required=True)
    e = sub.add_parser("eds", help="write the EDS file of a drive model",
                       description="Write the EDS (electronic data sheet) of a drive model, "
                                   "generated from its object dictionary data file.")
    e.add_argument("model", metavar="MODEL", help="drive model, e.g. hcfa-am0520b, kinco-servo")
    e.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of stdout")
    e.set_defaults(func=cmd_eds)
    m = sub.add_parser("models", help="list the drive models")
    m.set_defaults(func=cmd_models)


#: The name ``plcrt.cli`` looks for in command modules.
register = add_parser


def cmd_eds(args: argparse.Namespace) -> int:
    """Print or write the EDS text; errors are PlcErrors for ``plcrt.cli``."""
    from .canopen_od import eds_text   # perf: the command line imports this module at start

    text = eds_text(args.model)
    if args.output is None:
        sys.stdout.write(text)
        return 0
    try:
        Path(args.output).write_text(text, encoding="utf-8")
    except OSError as e:
        raise PlcConfigError(f"cannot write {args.output}: {e.strerror or e}") from None
    print(f"{args.model}: EDS written to {args.output}", file=sys.stderr)
    return 0


def cmd_models(args: argparse.Namespace) -> int:
    """List the available drive models, one per line."""
    from .canopen_od import models     # perf: as in cmd_eds

    for name in models():
        print(name)
    return 0
