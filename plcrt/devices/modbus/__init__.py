"""The Modbus RTU master library of Micro/WIN (MBUS_CTRL, MBUS_MSG) as
built-in blocks (:mod:`.master`), the Modbus RTU slave a plant file puts at
a port (:mod:`.slave`), and the protocol's frames and CRC (:mod:`.rtu`).
docs/modbus.md describes all three."""
