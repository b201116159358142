"""Simulated CiA 402 bus drives: the HCFA AM0520B EtherCAT stepper and a Kinco
servo (HCFA manual, Kinco homing slides; the model and its decisions are in
docs/cia402.md).

:mod:`.od` holds the object dictionary (loaded from ``library/cia402/*.toml``)
and :mod:`.store` the live values with their SDO rules; the CiA 402 power
states are in :mod:`.statemachine` over the tables of :mod:`.states` and
:mod:`.reactions`, the EtherCAT states in :mod:`.esm`, the PDO mapping rules
in :mod:`.pdo`, the homing methods in :mod:`.homing_methods` and
:mod:`.homing`; :mod:`.cli` is the ``plcrt cia402`` command.  The modes
and the bus ports build on them.  The public facade is
:mod:`plcrt.cia402`.
"""
