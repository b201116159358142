"""The browser panel (``plcrt serve``): a local web page that runs a
program scan-exact and shows its ladder with live status, the inputs as
switches and push-buttons, the outputs as lamps, a watch table, trends and
the axes of the plant.

:mod:`plcrt.web.session` runs the PLC (no web code in it) and composes
:mod:`~plcrt.web.running` (run modes), :mod:`~plcrt.net.pacing` (speed),
:mod:`~plcrt.web.builds` (breakpoints), :mod:`~plcrt.web.watch` (watch
table, set and force), :mod:`~plcrt.web.trend` and
:mod:`~plcrt.web.program` (the program as the pages draw it),
:mod:`plcrt.web.protocol` is the one message schema of the websocket,
:mod:`plcrt.web.svg` draws rungs from :mod:`plcrt.view`'s model,
:mod:`plcrt.web.course` lists lessons and checks them,
:mod:`plcrt.web.server` is the aiohttp application and
:mod:`plcrt.web.cli` the ``serve`` subcommand.  The page itself is plain
HTML, CSS and JavaScript under ``static/``: no build step, no network.
"""

from __future__ import annotations

__all__: list[str] = []
