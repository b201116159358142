"""The library blocks plcrt's devices implement, in one list.

What it is: importing this module imports every module of
:mod:`plcrt.devices` that registers built-in library blocks with
:func:`plcrt.blocks.register_block` (and the protected subroutines that
stand for them, :func:`plcrt.blocks.register_protected`).  The block
registry sits below the devices and never imports them: ``plcrt/__init__.py``
hands it the import of this module as a loader
(:func:`plcrt.blocks.add_library_loader`), run when a compiled call first
needs the table.  A new library family is one more line here.

What it is not: the blocks themselves, or their interfaces
(``library/*.toml``, :mod:`plcrt.blocks.interface`).
"""

from __future__ import annotations

from types import ModuleType

from .em253 import blocks as em253_blocks          # MOTION_EN3 ... HOMING, POS_RUN
from .ptowizard import blocks as ptowizard_blocks  # PTOx_CTRL/RUN/MAN/LDPOS/ADV, PWMx_RUN
from .modbus import master as modbus_master        # MBUS_CTRL, MBUS_MSG
from .uss import library as uss_library            # USS_INIT, USS_CTRL, USS_xPM_x
from .modbus import slavelib as modbus_slave       # MBUS_INIT, MBUS_SLAVE

__all__ = ["MODULES"]

#: Every module that registers library blocks, in the order they are imported.
MODULES: tuple[ModuleType, ...] = (em253_blocks, ptowizard_blocks, modbus_master, uss_library,
                                   modbus_slave)
