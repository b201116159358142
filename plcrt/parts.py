"""What the layers above the engine fit into every PLC, through one table.

What it is: :class:`Parts`, the narrow interface through which the engine
gets what it does not define itself -- the devices a plant describes
(stepped through :class:`plcrt.engine.device.Device`), the devices a plant
puts at the communication ports, what a parsed plant is (what
``Plc(plant=...)`` accepts), and the compiler hooks of the library blocks
(``CALL MBUS_CTRL``, and the export's protected subroutines that stand for
such blocks) -- and the one table that holds it (:func:`supply`,
:func:`supplied`).

The composition root fills it: ``plcrt/__init__.py`` hands this module a
loader (:func:`add_parts_loader`: the import of :mod:`plcrt.loader`, which
calls :func:`supply`), and :func:`supplied` runs it when a PLC is first
built.  So ``plcrt.Plc(...)``, ``plcrt.load(...)``, a fork and the test
harness all get the same parts.  The table sits at the bottom of the
layers, beside :mod:`plcrt.errors` (it imports nothing of plcrt): the
engine reads it, and ``import plcrt`` hands it the loader without loading
the engine.

What it is not: any device or library block, nor the engine.  The engine
never imports :mod:`plcrt.devices` or :mod:`plcrt.blocks`; they sit above
it and reach it only through this table and the objects it hands back.
Without a loader (the engine used on its own) a PLC has no devices, no
plant is accepted and a ``CALL`` of a library block is an unknown
subroutine.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

__all__ = ["Parts", "add_parts_loader", "supplied", "supply"]


def _never(x: Any) -> bool:
    return False


def _no_devices(plc: Any, plant: Any) -> list[Any]:
    return []


def _no_port_devices(ports: list[Any], plant: Any) -> None:
    return None


@dataclass(frozen=True)
class Parts:
    """The parts a PLC is fitted with (see the module docstring).

    The engine reads a plant only as duck-typed configuration: ``wiring``,
    ``encoders``, ``clock``, ``ports`` (``address``, ``ppi_baud``,
    ``where``) and ``ethernet``; everything else in it is for the two
    builders here.
    """

    #: ``is_plant(x)``: whether *x* is a parsed plant (``Plc(plant=...)``'s check)
    is_plant: Callable[[Any], bool] = _never
    #: ``build_devices(plc, plant)``: the devices the plant describes
    #: (:class:`plcrt.engine.device.Device`), in the order the scan steps
    #: them (called while the PLC is built)
    build_devices: Callable[[Any, Any], list[Any]] = _no_devices
    #: ``attach_port_devices(ports, plant)``: put the plant's devices at
    #: the ports (called last, once the PLC's time line exists)
    attach_port_devices: Callable[[list[Any], Any], None] = _no_port_devices
    #: hooks of the compiled unit (``unit.hooks``) by name: ``library_call``
    #: and ``protected_call`` (:mod:`plcrt.isa.control`'s CALL asks them)
    compile_hooks: Mapping[str, Callable[..., Any]] = field(default_factory=dict)


_SUPPLIED: list[Parts] = [Parts()]

#: loaders not run yet (see :func:`add_parts_loader`)
_PENDING: list[Callable[[], object]] = []


def add_parts_loader(loader: Callable[[], object]) -> None:
    """Hand the table a function that supplies the parts (by importing the
    module that calls :func:`supply`); it runs once, at the first
    :func:`supplied`."""
    _PENDING.append(loader)


def supply(parts: Parts) -> None:
    """Fit every PLC built from now on with *parts*."""
    _SUPPLIED[0] = parts


def supplied() -> Parts:
    """The parts to fit a PLC with, after running the loaders not run yet
    (cheap once they have run)."""
    while _PENDING:
        _PENDING[0]()
        del _PENDING[0]    # after it returned: a loader that raised is tried again
    return _SUPPLIED[0]
