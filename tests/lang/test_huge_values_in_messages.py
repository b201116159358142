"""A value that cannot be printed as it is (a list holding an integer of
more than 4300 digits, whose repr() Python refuses) is named in a
PlcConfigError by its kind, never raised as a ValueError: the file-size
limit and the plant's numbers."""

from __future__ import annotations

import pytest

import plcrt
from plcrt.devices.plant import load_plant
from plcrt.errors import PlcConfigError

HUGE = [10 ** 5000]

PROGRAM = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD SM0.0
= Q0.0
END_ORGANIZATION_BLOCK
"""


def test_the_file_size_limit_names_a_list_holding_a_huge_integer() -> None:
    with pytest.raises(PlcConfigError, match="huge integer"):
        plcrt.load(PROGRAM, max_file_mb=HUGE)


def test_a_plant_number_that_is_a_list_holding_a_huge_integer() -> None:
    with pytest.raises(PlcConfigError, match="huge integer"):
        load_plant({"module": {"0": {"axis": {"0": {"start": HUGE}}}}})


def test_a_plant_dict_with_keys_that_are_not_texts() -> None:
    with pytest.raises(PlcConfigError, match="unknown key"):
        load_plant({1: 2, "b": 3})
