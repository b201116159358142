"""Built-in blocks: library instructions (e.g. the EM253 library) that
programs call with ``CALL NAME, args...`` like Micro/WIN library
subroutines, implemented in Python.

* :mod:`.interface` reads the interface descriptions in ``library/*.toml``.
* :mod:`.call` is the compiler hook that checks a call against its
  interface and emits the code that passes arguments and writes results.
* This module is the registry that hook reads.  Implementations register a
  factory with :func:`register_block`; the factory gets the running
  :class:`~plcrt.engine.runtime.Plc` and the call site's location and
  returns the callable the generated code calls.  Blocks that an export
  holds as protected subroutines are declared with :func:`register_protected`.

What it is not: the implementations.  They live in the layer above
(:mod:`plcrt.devices`: the EM253, the pulse-output wizards, Modbus, USS) and
register themselves when their module is imported; the registry never
imports them.  Whoever composes the layers hands the registry a loader
(:func:`add_library_loader`: ``plcrt/__init__.py`` hands it the import of
:mod:`plcrt.devices.libraries`, the list of plcrt's library modules), and
:func:`load_libraries` runs it when a call first needs the table.
"""

from __future__ import annotations

from typing import Any, Callable

__all__ = ["BLOCK_FACTORIES", "PROTECTED", "add_library_loader", "load_libraries",
           "register_block", "register_protected"]

#: block name (upper case) -> factory(plc, loc, interface) -> callable
BLOCK_FACTORIES: dict[str, Callable[..., Callable[..., tuple]]] = {}

#: export block name -> (the interfaces it may stand for, in the order tried;
#: the family named in warnings), filled by :func:`register_protected`
PROTECTED: dict[str, tuple[tuple[str, ...], str]] = {}

#: loaders not run yet (see :func:`add_library_loader`)
_PENDING: list[Callable[[], object]] = []


def register_block(name: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorator registering the implementation factory of a library block."""

    def deco(factory: Callable[..., Any]) -> Callable[..., Any]:
        BLOCK_FACTORIES[name.upper()] = factory
        return factory

    return deco


def register_protected(family: str, names: dict[str, tuple[str, ...]]) -> None:
    """Declare library blocks that an export holds as protected subroutines
    (an interface and an empty body): a CALL of a program subroutine named
    like one of *names* runs the built-in block whose interface matches."""
    for name, variants in names.items():
        PROTECTED[name.upper()] = (variants, family)


def add_library_loader(loader: Callable[[], object]) -> None:
    """Hand the registry a function that registers library blocks (by
    importing the modules that call :func:`register_block`); it runs once,
    at the first :func:`load_libraries`."""
    _PENDING.append(loader)


def load_libraries() -> None:
    """Run the loaders not run yet, so that :data:`BLOCK_FACTORIES` and
    :data:`PROTECTED` hold every library block (cheap once they have run)."""
    while _PENDING:
        _PENDING[0]()
        del _PENDING[0]    # after it returned: a loader that raised is tried again
