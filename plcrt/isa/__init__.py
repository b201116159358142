"""The instruction set: one emitter per STL mnemonic, by family.

Importing this package registers every family's instructions in
:mod:`.registry` (the family modules import the registry, never the other
way round).  The emitters are written against :mod:`plcrt.gen` (the
generator ``Gen``, the operand types, the resolver and the limits), which
lies below this package; the compiler (:mod:`plcrt.compiler`) lies above it
and drives the emitters through the registry.
"""

from . import families  # noqa: F401  (each family registers its mnemonics)
