"""What the command-line front ends share, below all of them.

``plcrt run``, ``show``, ``trace``, ``debug`` and ``serve`` read the same
options and load, run and report a program the same way.  What they share
lives here, so that no front end imports another:

* :mod:`.options`: the program, run-length, long-run and ``--set`` options,
  their checks, and loading a program from the parsed command line;
* :mod:`.report`: exit statuses and diagnostics printed GNU-style;
* :mod:`.progress`: running a PLC for a long time (progress bar or lines,
  the ``--max-wall`` limit, the longest run plcrt counts);
* :mod:`.tables`: the tables of axes, drives, pulse outputs, counters and
  ports (``plcrt run`` and the debugger).

This package imports no front end (:mod:`plcrt.cli`, :mod:`plcrt.debug`,
:mod:`plcrt.trace`, :mod:`plcrt.view`, :mod:`plcrt.web`,
:mod:`plcrt.testing`); they import it.  It holds no PLC semantics: values
are checked by :mod:`plcrt.engine.values` and runs are :meth:`plcrt.Plc.run`
and :meth:`plcrt.Plc.scan`.  Nothing is imported here, so that
``plcrt --help`` loads only the modules it needs.
"""
