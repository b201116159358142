"""The Micro/WIN wizards of the CPU's built-in pulse outputs: PTOx_CTRL,
PTOx_RUN, PTOx_MAN, PTOx_LDPOS, PTOx_ADV and PWMx_RUN over the PLS model
(:mod:`plcrt.engine.pulse`).  :mod:`.config` reads the plant file's
``[pto.N]`` / ``[pwm.N]``, :mod:`.plan` turns ramps into PTO trains,
:mod:`.blocks` implements the blocks.  Model and decisions:
docs/pto-wizard.md.
"""
