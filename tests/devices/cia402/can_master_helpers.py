"""The canopen master side of the CiA 402 bus tests (test_can_pdo.py,
test_can_bus.py): the documented master node, canopen's own remapping,
the CSP trajectory they follow, and waiting for a receiver thread."""

from __future__ import annotations

import threading
import time

from canopen.profiles.p402 import BaseNode402

from plcrt import cia402


def wait_for(cond, timeout=2.0):
    """Frames are handled in the receivers' Notifier threads."""
    end = time.monotonic() + timeout
    while not cond() and time.monotonic() < end:
        time.sleep(0.0005)
    return cond()


class Frames:
    """Every frame the master's network receives on the given identifiers."""

    def __init__(self, network, *ids):
        self.got: dict[int, list[bytes]] = {i: [] for i in ids}
        self.cond = threading.Condition()
        for i in ids:
            network.subscribe(i, self._on)

    def _on(self, can_id, data, timestamp):
        with self.cond:
            self.got[can_id].append(bytes(data))
            self.cond.notify_all()

    def wait(self, can_id, count, timeout=2.0):
        """The frames of ``can_id`` once there are ``count`` (or at the timeout)."""
        with self.cond:
            self.cond.wait_for(lambda: len(self.got[can_id]) >= count, timeout)
            return list(self.got[can_id])

    def wait_all(self, count, timeout=5.0):
        """Until every identifier has ``count`` frames (or the timeout)."""
        with self.cond:
            self.cond.wait_for(lambda: all(len(v) >= count for v in self.got.values()), timeout)


def master(mst, node_id, model="hcfa-am0520b"):
    """The documented master: the CAN view's dictionary, PDOs read from the node."""
    n = BaseNode402(node_id, cia402.object_dictionary(model, node_id=node_id))
    mst.add_node(n)
    n.nmt.state = "PRE-OPERATIONAL"
    n.setup_402_state_machine(read_pdos=True)
    return n


def remap_sync(n, sim, rx=(0x6040, 0x607A), tx=(0x6064, 0x6041), trans=1):
    """Remap the CAN view's PDOs with canopen's own procedure (save())."""
    tpdo, rpdo = n.tpdo[sim.tpdo_no], n.rpdo[sim.rpdo_no]
    for pdo, objs in ((tpdo, tx), (rpdo, rx)):
        pdo.clear()
        for index in objs:
            pdo.add_variable(index)
        pdo.trans_type = trans
        pdo.enabled = True
        pdo.save()
    return tpdo, rpdo


def trajectory(k: int) -> int:
    """A smooth move: 5 k^2 up to k = 60 (steps below 6080h = 833 P/ms), then on at 600/ms."""
    return 5 * k * k if k <= 60 else 18_000 + 600 * (k - 60)
