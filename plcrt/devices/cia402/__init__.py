"""Simulated CiA 402 bus drives: the HCFA AM0520B EtherCAT stepper and a Kinco
servo (HCFA manual, Kinco homing slides; digest in docs/cia402.md).

The package holds the drive's object dictionary, its state machines (CiA 402
power states in :mod:`.statemachine` over the tables of :mod:`.states` and
:mod:`.reactions`, EtherCAT states in :mod:`.esm`) and its PDO mapping rules
(:mod:`.pdo`); the modes, homing and the bus ports build on them."""
