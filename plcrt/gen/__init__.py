"""What instruction emitters are written against.

The layer between the instruction set (:mod:`plcrt.isa`, above) and the
front end and memory model (:mod:`plcrt.lang`, :mod:`plcrt.memory`, below):

* :mod:`.operands`: operand text to typed operands (``Addr``, ``Const``,
  ``Pointer``, ``Indirect``);
* :mod:`.roles`: what an instruction accepts at each operand position;
* :mod:`.resolve`: symbols and ``#locals`` resolved, operands checked
  against their roles (``Resolver``, ``ResolveError``, ``check_role``);
* :mod:`.emit`: ``Gen``, the per-function source builder with the static
  logic stack, and :mod:`.exprs`, the expression text it builds;
* :mod:`.rt`: the helpers generated code calls at run time;
* :mod:`.limits`: nesting and stack limits.

It is not the compiler: splitting blocks into functions, the call graph,
probes and ``compile()`` are :mod:`plcrt.compiler`'s, which drives the
emitters through the registry.  Nothing here imports ``plcrt.isa`` or
anything above it.
"""
