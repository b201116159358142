"""An in-process CAN bus that delivers every frame at once, in the sender's thread.

What it is: :class:`LocalBus`, a python-can ``BusABC`` whose ``send`` hands
the frame to every other bus on the same channel before it returns, and
:class:`LocalNetwork`, a ``canopen.Network`` connected to one (no Notifier
thread: the frames a network receives are dispatched to its listeners by
the sender).  Masters stay canopen's own (``RemoteNode``, ``BaseNode402``,
their ``tpdo``/``rpdo``, ``network.sync``); drives are attached with
:func:`plcrt.cia402.attach` as on python-can's ``virtual`` bus, which keeps
working unchanged.

Why: python-can's ``virtual`` bus deep-copies every frame for every
receiver and each ``canopen.Network`` polls it from a Notifier thread, so a
frame costs two queue hand-offs and a thread switch.  Here a SYNC sent by a
master runs the drives' bus cycles and their TPDOs reach the master's maps
before ``sync.transmit()`` returns: a cycle of eight drives is one call
chain, and its cost is the drives' and canopen's own.

Aliasing rule: a frame is not copied.  All receivers get the sender's
``can.Message`` (its ``timestamp`` set to the time of sending); its data is
the buffer the sender gave (canopen's ``rpdo.transmit()`` gives the map's
own buffer).  A sender does not change a message or its data after
``send`` returns; a receiver treats them as read-only and copies what it
keeps past its callback (the drive's port copies every frame it keeps;
canopen's master keeps a TPDO's data, which is the frame's own).

Threads: delivery runs in the sending thread with no lock of the bus held,
so a receiver may send from its callback (a master answering a TPDO with an
RPDO).  Frames sent by python-can's periodic tasks (``network.sync.start``,
heartbeats) arrive from their threads; each party serialises with its own
locks (the drive with its store lock, canopen with its conditions).

What it is not: no arbitration, bit timing, error frames or bus load; no
``recv()`` (frames are delivered, never polled: ``recv`` returns None); not
reachable through ``can.Bus(interface=...)`` (a ``canopen.Network``
connected that way would poll it from a Notifier thread).
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Any, Optional

import can
import canopen
from canopen.network import MessageListener, NodeScanner

from ...errors import PlcConfigError

__all__ = ["Frame", "LocalBus", "LocalNetwork", "MAX_CHANNEL"]

#: The longest channel name taken (a name is a key of this process's table).
MAX_CHANNEL = 64

_channels: dict[str, tuple["LocalBus", ...]] = {}
_channels_lock = threading.Lock()
_canopen_log = logging.getLogger("canopen.network")   # where canopen's listener logs


class Frame(can.Message):
    """A ``can.Message`` built with only what a CAN 2.0 frame of canopen
    needs (perf: ``can.Message.__init__`` takes thirteen arguments)."""

    __slots__ = ()

    def __init__(self, can_id: int, data: Any, remote: bool = False) -> None:  # noqa: D107
        self.timestamp = 0.0
        self.arbitration_id = can_id
        self.is_extended_id = can_id > 0x7FF
        self.is_remote_frame = remote
        self.is_error_frame = False
        self.channel = None
        self.is_fd = False
        self.is_rx = True
        self.bitrate_switch = False
        self.error_state_indicator = False
        self.data = data = bytearray() if remote or data is None else (
            data if data.__class__ is bytearray else bytearray(data))
        self.dlc = len(data)


class LocalBus(can.BusABC):
    """One party on in-process channel *channel*: ``send`` delivers the frame
    to the ``listeners`` of every other bus on the channel, in order of
    joining, before it returns."""

    def __init__(self, channel: str = "plcrt", **kwargs: Any) -> None:
        super().__init__(channel=channel, **kwargs)
        self.channel = channel
        self.channel_info = f"plcrt in-process CAN channel {channel!r}"
        #: The receivers of this party (``can.Listener``); a LocalNetwork
        #: puts its dispatch here.
        self.listeners: list[Any] = []
        #: How a frame reaches this party (a LocalNetwork puts its dispatch here).
        self.deliver = self._to_listeners
        #: The LocalNetwork on this bus, if any (:meth:`send_base` hands it
        #: an 11-bit data frame as canopen's listener would).
        self.network: Optional["LocalNetwork"] = None
        self._open = True
        with _channels_lock:
            _channels[channel] = _channels.get(channel, ()) + (self,)

    def send(self, msg: can.Message, timeout: Optional[float] = None) -> None:
        if not self._open:
            raise can.CanOperationError(f"{self.channel_info} is shut down")
        msg.timestamp = time.time()
        for bus in _channels.get(self.channel, ()):     # perf: a tuple, replaced on join/leave
            if bus is not self:
                bus.deliver(msg)

    def send_base(self, can_id: int, data: Any) -> None:
        """Send an 11-bit data frame *can_id* with *data* as :meth:`send`
        sends ``Frame(can_id, data)``: a party whose LocalNetwork's only
        listener is canopen's (``LocalNetwork._deliver``'s common case) gets
        it by ``notify`` directly; a ``Frame`` is built, once, for any other."""
        if not self._open:
            raise can.CanOperationError(f"{self.channel_info} is shut down")
        # perf: no can.Message for the parties that take (id, data, time),
        # and no send/_deliver calls in between (17 frames per CSP cycle of
        # eight drives); the data as a Frame holds it
        if data.__class__ is not bytearray:
            data = bytearray() if data is None else bytearray(data)
        now = time.time()
        msg = None
        for bus in _channels.get(self.channel, ()):     # perf: a tuple, replaced on join/leave
            if bus is self:
                continue
            net = bus.network
            if net is not None:
                listeners = net.listeners
                if len(listeners) == 1 and (listeners[0] is net._plain
                                            or net._plain_head(listeners[0])):
                    try:
                        net.notify(can_id, data, now)
                    except Exception as e:
                        _canopen_log.error(str(e))
                    continue
            if msg is None:
                msg = Frame(can_id, data)
                msg.timestamp = now
            bus.deliver(msg)

    def _to_listeners(self, msg: can.Message) -> None:
        for listener in self.listeners:
            listener.on_message_received(msg)

    def _recv_internal(self, timeout: Optional[float]) -> tuple[None, bool]:
        return None, False                            # frames are delivered, not polled

    def shutdown(self) -> None:
        if self._open:
            self._open = False
            with _channels_lock:
                rest = tuple(b for b in _channels.get(self.channel, ()) if b is not self)
                if rest:
                    _channels[self.channel] = rest
                else:
                    _channels.pop(self.channel, None)
        super().shutdown()


class _Dispatch:
    """What a ``canopen.Network`` keeps as its notifier: the list of its
    listeners (which the bus calls) and no thread."""

    exception = None

    def __init__(self, listeners: list[Any]) -> None:
        self.listeners = listeners

    def add_listener(self, listener: Any) -> None:
        self.listeners.append(listener)

    def remove_listener(self, listener: Any) -> None:
        self.listeners.remove(listener)

    def stop(self, timeout: float = 5.0) -> None:
        for listener in self.listeners:
            listener.stop()


class LocalNetwork(canopen.Network):
    """A ``canopen.Network`` on a :class:`LocalBus`: ``connect(channel)``
    joins the in-process channel; frames sent to it are dispatched in the
    sender's thread."""

    _plain: Any = None          # the one listener seen to hand 11-bit frames to notify

    def connect(self, channel: str = "plcrt", **kwargs: Any) -> "LocalNetwork":  # type: ignore[override]
        """Join in-process channel *channel*.

        Raises:
            PlcConfigError: connected already, or a python-can argument
                (``interface=``, ``bitrate=``...), which this bus has not.
        """
        if self.bus is not None:
            raise PlcConfigError(f"cia402.bus: the network is connected to "
                                 f"{self.bus.channel_info} already")
        if kwargs:
            raise PlcConfigError("cia402.bus: an in-process network takes a channel only, not "
                                 + ", ".join(sorted(k for k in kwargs if isinstance(k, str))[:8]))
        bus = self.bus = LocalBus(channel)
        self.notifier = _Dispatch(self.listeners)
        bus.listeners = self.listeners
        bus.deliver = self._deliver
        bus.network = self
        return self

    def _deliver(self, msg: can.Message) -> None:
        """A frame from the channel: as the listeners would take it, with
        the common case -- an 11-bit data frame and the network's own
        dispatch as the only listener -- handed to ``notify`` directly."""
        listeners = self.listeners
        if (len(listeners) == 1 and not (msg.is_extended_id or msg.is_remote_frame
                                         or msg.is_error_frame)
                and (listeners[0] is self._plain or self._plain_head(listeners[0]))):
            # perf: what canopen's MessageListener does with such a frame,
            # without the calls in between
            try:
                self.notify(msg.arbitration_id, msg.data, msg.timestamp)
            except Exception as e:
                _canopen_log.error(str(e))
            return
        for listener in listeners:
            listener.on_message_received(msg)

    def _plain_head(self, listener: Any) -> bool:
        """Whether *listener* hands an 11-bit data frame to this network's
        ``notify`` and does nothing else: canopen's MessageListener of this
        network, or a filter that says so (``passes_base_frames_to``)."""
        inner = getattr(listener, "passes_base_frames_to", listener)
        if inner.__class__ is MessageListener and inner.network is self:
            self._plain = listener
            return True
        return False

    def notify(self, can_id: int, data: bytearray, timestamp: float) -> None:
        """As canopen's ``Network.notify``: the subscribers of *can_id*, then
        the node scanner."""
        callbacks = self.subscribers.get(can_id)
        if callbacks is not None:
            for callback in callbacks:
                callback(can_id, data, timestamp)
        scanner = self.scanner
        if scanner.__class__ is NodeScanner:
            # perf: NodeScanner.on_message_received written out (17 frames
            # per CSP cycle of eight drives)
            node_id = can_id & 0x7F
            if node_id and node_id not in scanner.nodes and (can_id & 0x780) in scanner.SERVICES:
                scanner.nodes.append(node_id)
        else:
            scanner.on_message_received(can_id)

    def send_message(self, can_id: int, data: bytes, remote: bool = False) -> None:
        """As canopen's, without its send lock: delivery runs receivers, and a
        receiver that sends on this network from its callback must not wait
        for the lock its own sender holds."""
        bus = self.bus
        if not bus:
            raise RuntimeError("Not connected to CAN bus")
        if remote or can_id > 0x7FF:
            bus.send(Frame(can_id, data, remote))
        else:
            bus.send_base(can_id, data)     # perf: no can.Message where none is needed
