"""Views of a program for people: ladder (LAD) drawings of STL networks,
with live status from a running PLC (``plcrt show``).

:mod:`plcrt.view.ladder` turns a network into a LAD model (pure data),
:mod:`plcrt.view.status` reads live values and evaluates power flow,
:mod:`plcrt.view.render` draws (the only module here that uses rich) and
:mod:`plcrt.view.cli` is the ``show`` subcommand.  The editable ladder
model is :mod:`plcrt.view.ladder_model` (the data and its JSON),
:mod:`plcrt.view.ladder_stl` (STL to model and back, exactly),
:mod:`plcrt.view.ladder_check` (its checks) and
:mod:`plcrt.view.ladder_edit` (edit operations, undo/redo, the page's
JSON functions).  Nothing here changes how a program runs.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .ladder import Ladder, to_ladder
    from .ladder_edit import History, apply_edit, edit_json, model_json
    from .ladder_stl import NoLadder, model_to_stl, network_to_model
    from .status import PlcStatus

__all__ = ["History", "Ladder", "NoLadder", "PlcStatus", "apply_edit", "edit_json", "model_json",
           "model_to_stl", "network_to_model", "to_ladder"]

#: public name -> the module that defines it (imported on first use)
_LAZY = {"Ladder": "ladder", "to_ladder": "ladder", "PlcStatus": "status",
         "History": "ladder_edit", "apply_edit": "ladder_edit", "edit_json": "ladder_edit",
         "model_json": "ladder_edit", "NoLadder": "ladder_stl", "model_to_stl": "ladder_stl",
         "network_to_model": "ladder_stl"}


def __getattr__(name: str) -> Any:
    # perf: `plcrt --help` imports plcrt.view.cli to register `show`; the
    # ladder model needs the compiler (and lark), loaded only when drawing
    if name in _LAZY:
        import importlib
        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
