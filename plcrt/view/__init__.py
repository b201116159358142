"""Views of a program for people: ladder (LAD) drawings of STL networks,
with live status from a running PLC (``plcrt show``).

:mod:`plcrt.view.ladder` turns a network into a LAD model (pure data),
:mod:`plcrt.view.status` reads live values and evaluates power flow,
:mod:`plcrt.view.render` draws (the only module here that uses rich) and
:mod:`plcrt.view.cli` is the ``show`` subcommand.  Nothing here changes how
a program runs.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .ladder import Ladder, to_ladder
    from .status import PlcStatus

__all__ = ["Ladder", "PlcStatus", "to_ladder"]

#: public name -> the module that defines it (imported on first use)
_LAZY = {"Ladder": "ladder", "to_ladder": "ladder", "PlcStatus": "status"}


def __getattr__(name: str) -> Any:
    # perf: `plcrt --help` imports plcrt.view.cli to register `show`; the
    # ladder model needs the compiler (and lark), loaded only when drawing
    if name in _LAZY:
        import importlib
        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
