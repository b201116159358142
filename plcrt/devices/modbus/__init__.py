"""The Modbus RTU master library of Micro/WIN (MBUS_CTRL, MBUS_MSG) and its
slave library (MBUS_INIT, MBUS_SLAVE) as built-in blocks (:mod:`.master`,
:mod:`.slavelib`), the Modbus RTU slave and master a plant file puts at a
port (:mod:`.slave`, :mod:`.plantmaster`), and the protocol's frames, CRC
and a slave's answer (:mod:`.rtu`).  docs/modbus.md describes them all."""
