"""The simulated EM253 two-axis positioning module and its instruction
library (EM253 user manual).  :mod:`.axis` is one axis, :mod:`.module` the
module with its terminals, :mod:`.homing` the 14 homing modes and
:mod:`.blocks` (with :mod:`.moves` and
:mod:`.pos_run`) the seven library instructions."""
