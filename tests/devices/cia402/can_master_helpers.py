"""The canopen master side of the CiA 402 bus tests (test_can_pdo.py,
test_can_bus.py): the documented master node, canopen's own remapping,
the CSP trajectory they follow, and waiting for a receiver thread."""

from __future__ import annotations

import time

from canopen.profiles.p402 import BaseNode402

from plcrt import cia402


def wait_for(cond, timeout=2.0):
    """Frames are handled in the receivers' Notifier threads."""
    end = time.monotonic() + timeout
    while not cond() and time.monotonic() < end:
        time.sleep(0.0005)
    return cond()


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
