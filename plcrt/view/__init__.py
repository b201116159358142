"""Views of a program for people: ladder (LAD) drawings of STL networks,
with live status from a running PLC (``plcrt show``).

:mod:`plcrt.view.ladder` turns a network into a LAD model (pure data),
:mod:`plcrt.view.status` reads live values and evaluates power flow,
:mod:`plcrt.view.render` draws (the only module here that uses rich) and
:mod:`plcrt.view.cli` is the ``show`` subcommand.  Nothing here changes how
a program runs.
"""

from __future__ import annotations

from .ladder import Ladder, to_ladder
from .status import PlcStatus

__all__ = ["Ladder", "PlcStatus", "to_ladder"]
