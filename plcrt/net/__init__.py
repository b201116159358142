"""A running PLC on the network: the S7 and Modbus servers, serial ports
on pseudo-terminals, and lockstep co-simulation.

Layout: :mod:`.door` (requests run at a scan boundary), :mod:`.runner`
(the thread that runs the PLC in real time or in lockstep), :mod:`.pacing`
(the speed), :mod:`.options` (addresses, limits, the write allow-list),
:mod:`.tcp` (what every TCP server shares), :mod:`.host` (the servers'
loop and their start and stop), :mod:`.serving` (``plcrt.serve``) and one
module or package per protocol.  See docs/network.md.

Nothing here imports the panel, the debugger or the command line; they
import this.
"""

from .door import ScanDoor
from .host import Serving
from .options import ServerOptions, WriteGuard
from .runner import Runner
from .serving import serve

__all__ = ["Runner", "ScanDoor", "ServerOptions", "Serving", "WriteGuard", "serve"]
