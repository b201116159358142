"""Built-in blocks: library instructions (e.g. the EM253 library) that
programs call with ``CALL NAME, args...`` like Micro/WIN library
subroutines, implemented in Python.

* :mod:`.interface` reads the interface descriptions in ``library/*.toml``.
* :mod:`.call` is the compiler hook that checks a call against its
  interface and emits the code that passes arguments and writes results.
* Implementations register a factory with :func:`register_block`; the
  factory gets the running :class:`~plcrt.engine.runtime.Plc` and the call
  site's location and returns the callable the generated code calls.
"""

from __future__ import annotations

from typing import Any, Callable

#: block name (upper case) -> factory(plc, loc, interface) -> callable
BLOCK_FACTORIES: dict[str, Callable[..., Callable[..., tuple]]] = {}


def register_block(name: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorator registering the implementation factory of a library block."""

    def deco(factory: Callable[..., Any]) -> Callable[..., Any]:
        BLOCK_FACTORIES[name.upper()] = factory
        return factory

    return deco
