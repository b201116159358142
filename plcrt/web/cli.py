"""The ``plcrt serve`` subcommand: the browser panel on a local port, and
the network servers (S7, Modbus TCP, lockstep) beside it or alone
(``--no-panel``).

Registered by :mod:`plcrt.cli` through :func:`register`.  Only argument
handling, loading and starting the servers live here; aiohttp is imported
when the panel starts, so other commands do not need it.  With the panel,
the panel's session runs the PLC and serves the network servers' door
(:mod:`plcrt.net.door`); without it, a :class:`plcrt.net.runner.Runner`
does.
"""

from __future__ import annotations

import argparse
import ipaddress
import sys
from pathlib import Path
from typing import Any

#: the default port (0: any free one)
DEFAULT_PORT = 8253


def register(sub: Any) -> None:
    """Add ``serve`` to the subparsers of the ``plcrt`` command."""
    from ..term.options import add_program_args, add_scan_ms_arg

    p = sub.add_parser(
        "serve", help="open a program in the browser panel (ladder, I/O, axes, trends)",
        description="Serve a local web page that runs the program scan-exact in simulated "
                    "time: ladder with live status, inputs as switches and push-buttons, "
                    "outputs as lamps, watch table, trends and the axes of the plant. "
                    "PROGRAM may be a lesson folder of the course (examples/course/NN-...).")
    add_program_args(p)
    add_scan_ms_arg(p)
    p.add_argument("--port", type=int, default=DEFAULT_PORT, metavar="N",
                   help=f"TCP port (default {DEFAULT_PORT}; 0 picks a free one)")
    p.add_argument("--host", default="127.0.0.1", metavar="ADDR",
                   help="address to listen on (default 127.0.0.1, this machine only)")
    p.add_argument("--allow-host", action="append", default=[], metavar="NAME",
                   help="a host name the page may be opened under, besides the address it "
                        "is served on and localhost (repeatable; other names are refused)")
    p.add_argument("--open", action="store_true", help="open the page in a web browser")
    p.add_argument("--no-breakpoints", action="store_true",
                   help="no breakpoints (scans never move to the build with network probes "
                        "that a breakpoint needs)")
    net = p.add_argument_group(
        "network servers", "HMIs, SCADA, plant simulators and S7 or Modbus client libraries "
        "connect to the running program (docs/network.md); each listens on this machine "
        "only unless a host is named (here or with --host)")
    net.add_argument("--s7", nargs="?", const="102", metavar="[HOST:]PORT",
                     help="S7 server (ISO-on-TCP; V memory is DB1); default port 102")
    net.add_argument("--modbus", nargs="?", const="502", metavar="[HOST:]PORT",
                     help="Modbus TCP server with the S7-200 Modbus slave map; default port 502")
    net.add_argument("--lockstep", metavar="[HOST:]PORT",
                     help="lockstep server: a client advances the PLC step by step "
                          "(JSON lines; plcrt.net.client.LockstepClient)")
    net.add_argument("--modbus-map", metavar="FILE",
                     help="a custom Modbus address map (TOML; docs/network.md) instead of "
                          "the slave library's")
    net.add_argument("--serial", type=int, action="append", default=[], metavar="PORT",
                     help="put CPU port PORT (0 or 1) on a pseudo-terminal, so a serial "
                          "program (a Modbus RTU master, a terminal) talks to the program's "
                          "freeport or MBUS_SLAVE through /dev/pts/N (repeatable)")
    net.add_argument("--no-panel", action="store_true",
                     help="no browser panel: only the network servers")
    net.add_argument("--speed", default="realtime", metavar="SPEED",
                     help="realtime (default), max, lockstep (only clients advance it) or "
                          "simulated seconds per wall second (2, 0.5)")
    net.add_argument("--read-only", action="store_true", help="clients may not write")
    net.add_argument("--allow-writes", metavar="RANGES",
                     help="the only addresses clients may write, e.g. VB0-VB99,I0.0-I1.7")
    net.add_argument("--max-connections", type=int, default=8, metavar="N",
                     help="clients per server at once (default 8; more are refused)")
    net.add_argument("--idle-timeout", type=float, default=60.0, metavar="S",
                     help="seconds a silent client keeps its connection (default 60; 0: "
                          "forever)")
    p.set_defaults(func=cmd_serve)


def build_panel(args: argparse.Namespace, door: Any = None) -> Any:
    """Load the program (or the lesson) of the command line into a
    :class:`~plcrt.web.server.Panel`.

    Raises:
        PlcError: the program does not load, or a bad option.
    """
    from ..term.options import load_from_args
    from ..term.report import print_diagnostics
    from . import course
    from .server import Panel
    from .session import PanelSession

    def load_lesson(les: course.Lesson) -> PanelSession:
        ns = argparse.Namespace(**vars(args))
        ns.programs = [str(les.program)]
        ns.symbols = str(les.symbols) if les.symbols else args.symbols
        ns.plant = str(les.plant) if les.plant else args.plant
        plc = load_from_args(ns, args.scan_ms)
        print_diagnostics(plc.diagnostics)
        return PanelSession(plc, breakpoints=not args.no_breakpoints, kinds=les.kinds(),
                            door=door)

    def source_of(les: course.Lesson | None) -> Any:
        # the program file the editor edits: the lesson's, else the first one
        from .editor import ProgramSource
        ns = argparse.Namespace(**vars(args))
        if les is not None:
            ns.programs = [str(les.program)]
            ns.symbols = str(les.symbols) if les.symbols else args.symbols
            ns.plant = str(les.plant) if les.plant else args.plant
        if Path(ns.programs[0]).suffix.lower() != ".awl":
            return None   # a project file (.mwp, .smart) is not edited as text
        return ProgramSource(Path(ns.programs[0]), tuple(Path(p) for p in ns.programs[1:]),
                             _load_options(ns))

    # --host NAME (not an address) is a name the page is opened under
    hosts = [*getattr(args, "allow_host", []),
             *([] if _is_address(getattr(args, "host", "")) else [getattr(args, "host", "")])]
    first = Path(args.programs[0])
    if len(args.programs) == 1 and first.is_dir():
        les = course.lesson(first)
        return Panel(load_lesson(les), lessons=course.lessons(first.parent), current=les,
                     load_lesson=load_lesson, hosts=hosts, source_of=source_of)
    plc = load_from_args(args, args.scan_ms)
    print_diagnostics(plc.diagnostics)
    current = None
    if course.is_lesson(first.parent) and first.name == "lesson.awl":
        current = course.lesson(first.parent)
    lessons = course.lessons(first.parent.parent) if current else []
    session = PanelSession(plc, breakpoints=not args.no_breakpoints,
                           kinds=current.kinds() if current else None, door=door)
    return Panel(session, lessons=lessons, current=current,
                 load_lesson=load_lesson if current else None, hosts=hosts, source_of=source_of)


def _load_options(args: argparse.Namespace) -> dict[str, Any]:
    """The keyword arguments of :func:`plcrt.load` that ``plcrt serve``'s
    options give (as ``load_from_args`` passes them), for the editor's
    texts."""
    data, plant = getattr(args, "data", None), getattr(args, "plant", None)
    return {"symbols": Path(args.symbols) if args.symbols else None,
            "data": Path(data) if data else None, "scan_ms": args.scan_ms,
            "cpu": getattr(args, "cpu", None),
            "pace": "realtime" if getattr(args, "realtime", False) else "simulated",
            "plant": Path(plant) if plant else None,
            "encoding": getattr(args, "encoding", None),
            "max_file_mb": getattr(args, "max_file_mb", None),
            "auto_symbols": getattr(args, "auto_symbols", False),
            "clock": getattr(args, "clock", None),
            "backend": getattr(args, "backend", None), "entry": getattr(args, "entry", None)}


def _is_address(host: str) -> bool:
    try:
        ipaddress.ip_address(host.strip("[]"))
    except ValueError:
        return False
    return True


def cmd_serve(args: argparse.Namespace) -> int:
    """``plcrt serve``: 0 after Ctrl-C, 1 a program, option or port error."""
    from ..term.report import EXIT_ERROR, EXIT_OK, print_diagnostics
    from ..errors import PlcConfigError, PlcError
    serving = None
    try:
        if not 0 <= args.port <= 65535:
            raise PlcConfigError(f"--port must be between 0 and 65535, got {args.port}")
        servers = _server_options(args)
        if args.no_panel:
            if not servers and not args.serial:
                raise PlcConfigError("--no-panel: name a server to run (--s7, --modbus, "
                                     "--lockstep or --serial)")
            return _serve_headless(args, servers, EXIT_OK)
        try:
            import aiohttp  # noqa: F401
        except ImportError:
            raise PlcConfigError("plcrt serve needs aiohttp: pip install aiohttp") from None
        from ..net.door import ScanDoor
        from ..net.runner import parse_speed
        speed = parse_speed(args.speed)
        door = ScanDoor()
        panel = build_panel(args, door)
        if servers or args.serial:
            serving = _serving(panel.session.plc, servers, args, runner=False,
                               door=door).start()
            _say_servers(serving)
            if speed == "lockstep":   # lockstep clients step it on the panel's thread
                door.speed = "lockstep"
            else:
                _panel_speed(panel.session, speed)
                panel.session.control.run(panel.session.plc)
    except PlcError as e:
        print_diagnostics(e.diagnostics)
        return EXIT_ERROR
    from ..net.options import exposed
    if exposed(args.host):
        print(f"plcrt serve: warning: listening on {args.host}: anyone who can reach this "
              f"address can run and force the PLC", file=sys.stderr)
    try:
        return _serve(panel, args.host, args.port, args.open, EXIT_OK, EXIT_ERROR)
    finally:
        if serving is not None:
            serving.close()


def _server_options(args: argparse.Namespace) -> dict[str, Any]:
    """The network servers the command line names, with their options."""
    from ..errors import PlcConfigError
    from ..net.options import Listen, ServerOptions, WriteGuard, exposed, parse_listen, \
        parse_ranges
    guard = WriteGuard(read_only=args.read_only,
                       allow=parse_ranges(args.allow_writes) if args.allow_writes else None)
    out: dict[str, Any] = {}
    for name in ("s7", "modbus", "lockstep"):
        spec = getattr(args, name)
        if spec is None:
            continue
        listen = parse_listen(spec, what=f"--{name}")
        if ":" not in spec:                     # no host of its own: --host's
            listen = Listen(args.host, listen.port)
        if exposed(listen.host):
            print(f"plcrt serve: warning: the {name} server listens on {listen.host}: anyone "
                  f"who can reach this address can read and write the PLC", file=sys.stderr)
        out[name] = ServerOptions(listen=listen, max_connections=args.max_connections,
                                  idle_timeout=args.idle_timeout, guard=guard)
    if args.modbus_map is not None:
        from ..net.modbus import with_map
        if "modbus" not in out:
            raise PlcConfigError("--modbus-map needs a Modbus server (--modbus)")
        out["modbus"] = with_map(out["modbus"], args.modbus_map)
    return out


def _serving(plc: Any, servers: dict[str, Any], args: argparse.Namespace,
             **kw: Any) -> Any:
    """The servers (and ``--serial`` ports) of the command line, not started."""
    from ..net.host import Serving
    from ..net.serial import pty_services
    serving = Serving(plc, servers, **kw)
    if args.serial:
        serving.services.update(pty_services(serving.door, plc,
                                             {n: "pty" for n in args.serial}))
    return serving


def _say_servers(serving: Any) -> None:
    for name, (host, port) in serving.addresses.items():
        if name.startswith("serial"):      # a port on a pseudo-terminal: its path
            print(f"plcrt port {name[6:]}: {host}", flush=True)
            continue
        shown = f"[{host}]" if ":" in host else host
        print(f"plcrt {name} server: {shown}:{port}", flush=True)


def _panel_speed(session: Any, speed: Any) -> None:
    if isinstance(speed, float):
        session.pacer.set("factor", speed, session.plc.now_us)
    else:
        session.pacer.set(speed, None, session.plc.now_us)


def _serve_headless(args: argparse.Namespace, servers: dict[str, Any], ok: int) -> int:
    """The network servers alone, until Ctrl-C (or SIGTERM)."""
    import signal
    import threading

    from ..term.options import load_from_args
    from ..term.report import print_diagnostics

    plc = load_from_args(args, args.scan_ms)
    print_diagnostics(plc.diagnostics)
    done = threading.Event()
    previous = signal.signal(signal.SIGTERM, lambda *_: done.set())
    try:
        with _serving(plc, servers, args, speed=args.speed) as serving:
            _say_servers(serving)
            print("(Ctrl-C stops)", flush=True)
            try:
                while not done.wait(0.5):
                    pass
            except KeyboardInterrupt:
                pass
            runner = serving.runner
            for e in runner.errors if runner is not None else []:
                print_diagnostics(e.diagnostics)
    finally:
        signal.signal(signal.SIGTERM, previous)
    return ok


def _serve(panel: Any, host: str, port: int, open_browser: bool, ok: int, bad: int) -> int:
    import asyncio

    from aiohttp import web

    from .server import make_app

    async def main() -> None:
        runner = web.AppRunner(make_app(panel))
        await runner.setup()
        site = web.TCPSite(runner, host, port)
        try:
            await site.start()
        except OSError as e:
            await runner.cleanup()
            raise SystemExit(f"plcrt serve: cannot listen on {host}:{port}: {e.strerror}")
        sockets = site._server.sockets if site._server else []  # type: ignore[union-attr]
        real = sockets[0].getsockname()[1] if sockets else port
        shown = f"[{host}]" if ":" in host else host
        url = f"http://{shown}:{real}/"
        print(f"plcrt panel: {url}  (Ctrl-C stops)", flush=True)
        if open_browser:
            import webbrowser
            webbrowser.open(url)
        panel.session.start()
        try:
            await asyncio.Event().wait()
        finally:
            panel.session.close()
            await runner.cleanup()

    try:
        asyncio.run(main())
    except KeyboardInterrupt:
        return ok
    except SystemExit as e:
        print(e.code, file=sys.stderr)
        return bad
    return ok


__all__ = ["DEFAULT_PORT", "build_panel", "cmd_serve", "register"]
