"""A connected page's inbox: the newest frame in one slot and a short queue
of messages.  The runner thread puts, the server's sender task takes; a
slow page skips frames and the scan never waits for it."""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any


class Mailbox:
    """One client's inbox: a one-slot frame (a newer frame replaces an
    unread one) and a short queue of messages (errors, notices).

    ``notify`` is called (from any thread) when something arrives; the
    server wakes its sender task with it."""

    def __init__(self, notify: Callable[[], None] | None = None) -> None:
        self._lock = threading.Lock()
        self._frame: dict[str, Any] | None = None
        self._messages: deque[dict[str, Any]] = deque(maxlen=100)
        self.notify = notify or (lambda: None)
        self.skipped = 0        #: frames replaced before they were read

    def put_frame(self, frame: dict[str, Any]) -> None:
        with self._lock:
            if self._frame is not None:
                self.skipped += 1
            self._frame = frame
        self.notify()

    def put(self, message: dict[str, Any]) -> None:
        with self._lock:
            self._messages.append(message)
        self.notify()

    def take(self) -> list[dict[str, Any]]:
        """Everything waiting: the messages in order, then the frame."""
        with self._lock:
            out = list(self._messages)
            self._messages.clear()
            if self._frame is not None:
                out.append(self._frame)
                self._frame = None
        return out


@dataclass
class Client:
    """One connected page."""

    mailbox: Mailbox
    view: str = "OB1"       #: the block whose networks it shows
    #: the networks on its screen ("OB1/3"), None: every network of the block
    nets: frozenset[str] | None = None


__all__ = ["Client", "Mailbox"]
