"""Simulated CiA 402 bus drives (HCFA AM0520B EtherCAT stepper, Kinco servo).

:mod:`.od` holds the object dictionary (loaded from ``library/cia402/*.toml``)
and the live values with their SDO rules; :mod:`.cli` the ``plcrt cia402``
command.  The public facade is :mod:`plcrt.cia402`.
"""
