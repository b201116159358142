"""Imports every instruction family so that each registers its mnemonics."""

from . import bitlogic  # noqa: F401
from . import compare  # noqa: F401
from . import move  # noqa: F401
from . import math_int  # noqa: F401
from . import math_real  # noqa: F401
from . import wordlogic  # noqa: F401
from . import convert  # noqa: F401
from . import timers  # noqa: F401
from . import counters  # noqa: F401
from . import control  # noqa: F401
from . import interrupts  # noqa: F401
from . import highspeed  # noqa: F401
from . import pid  # noqa: F401
from . import strings  # noqa: F401
from . import clock  # noqa: F401
from . import table  # noqa: F401
from . import ascii  # noqa: F401
from . import smart  # noqa: F401
from . import comm  # noqa: F401
