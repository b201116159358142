"""Modbus TCP for a served PLC, with the S7-200 Modbus slave library's
address map (:mod:`.addrmap`), its functions and exceptions (:mod:`.pdu`)
and MBAP framing over the shared TCP plumbing (:mod:`.server`).
docs/network.md, "Modbus TCP"."""

from .addrmap import DEFAULTS, AddressMap, Region, library_map, load_map
from .server import ModbusOptions, ModbusService, create, with_map

__all__ = ["AddressMap", "DEFAULTS", "ModbusOptions", "ModbusService", "Region", "create",
           "library_map", "load_map", "with_map"]
