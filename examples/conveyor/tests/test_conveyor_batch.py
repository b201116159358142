"""R4 batch and R5 reset: counting parts into batches."""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.plc("../conveyor.awl", symbols="../conveyor_symbols.txt",
                             data="../conveyor.db",
                             watch=["Part_Eye", "Part_Count", "Motor", "Batch_Lamp", "Jam_Eye",
                                    "Jam_Fault"])


def test_batch_size_comes_from_the_data_block(plc):
    """VW100 is 20 at power-up: the data block conveyor.db sets it."""
    assert plc["Batch_Size"] == 20


def test_twenty_parts_complete_a_batch_and_stop_the_belt(running, feed):
    """19 parts: the belt runs on.  The 20th part lights the batch lamp in
    the scan that counts it, and the belt stops in the next scan."""
    feed(19)
    assert running.values("Part_Count", "Motor", "Batch_Lamp") == {
        "Part_Count": 19, "Motor": 1, "Batch_Lamp": 0}
    running["Part_Eye"] = 1
    running.scan()
    assert running.values("Part_Count", "Motor", "Batch_Lamp") == {
        "Part_Count": 20, "Motor": 1, "Batch_Lamp": 1}
    running.scan()
    assert running["Motor"] == 0


@pytest.mark.parametrize("size", [1, 5, 12])
def test_batch_size_set_from_the_panel(running, feed, size):
    """The operator panel writes the batch size to VW100: the belt stops
    after exactly that many parts."""
    running["Batch_Size"] = size
    feed(size - 1)
    assert running["Motor"] == 1
    feed(1)
    assert running.values("Part_Count", "Motor", "Batch_Lamp") == {
        "Part_Count": size, "Motor": 0, "Batch_Lamp": 1}


def test_parts_are_not_counted_while_the_belt_is_stopped(ready):
    """Someone waves a hand in front of the part eye at standstill."""
    for _ in range(5):
        ready.pulse("Part_Eye")
        ready.scan()
    assert ready["Part_Count"] == 0


def test_reset_starts_a_new_batch(running, feed):
    """After a complete batch, start alone does nothing; reset clears the
    count and the lamp, then start runs the belt for the next batch."""
    feed(20)
    running.pulse("Start_PB")
    assert running["Motor"] == 0
    running.pulse("Reset_PB")
    assert running.values("Part_Count", "Batch_Lamp") == {"Part_Count": 0, "Batch_Lamp": 0}
    running.pulse("Start_PB")
    assert running["Motor"] == 1


def test_a_shift_from_stimulus_tables(running):
    """Twelve seconds of a shift as two time tables (seconds from the start
    of each): three parts, then a jam at 4 s that stops the belt at about
    7 s and is cleared at 8 s; the count survives the jam stop.  Then reset
    (which also starts a new batch), start, and two more parts."""
    running.stimulus([
        (0.5, "Part_Eye", 1), (0.7, "Part_Eye", 0),
        (1.5, "Part_Eye", 1), (1.7, "Part_Eye", 0),
        (2.5, "Part_Eye", 1), (2.7, "Part_Eye", 0),
        (4.0, "Jam_Eye", 1),
        (8.0, "Jam_Eye", 0),
    ], until=8.5)
    assert running.values("Motor", "Jam_Fault", "Fault_Lamp", "Part_Count") == {
        "Motor": 0, "Jam_Fault": 1, "Fault_Lamp": 1, "Part_Count": 3}
    running.stimulus([
        (0.0, "Reset_PB", 1), (0.1, "Reset_PB", 0),
        (0.5, "Start_PB", 1), (0.6, "Start_PB", 0),
        (1.5, "Part_Eye", 1), (1.7, "Part_Eye", 0),
        (2.5, "Part_Eye", 1), (2.7, "Part_Eye", 0),
    ], until=3.5)
    assert running.values("Motor", "Jam_Fault", "Fault_Lamp", "Part_Count") == {
        "Motor": 1, "Jam_Fault": 0, "Fault_Lamp": 0, "Part_Count": 2}


def test_fork_after_warm_up(running, feed):
    """Warm up once (19 parts, about 10 s), then fork two independent PLCs
    from that state: one gets the 20th part, the other a reset."""
    feed(19)
    last_part, reset = running.fork(), running.fork()

    last_part.pulse("Part_Eye")
    last_part.scan()
    assert last_part.values("Part_Count", "Motor", "Batch_Lamp") == {
        "Part_Count": 20, "Motor": 0, "Batch_Lamp": 1}

    reset.pulse("Reset_PB")
    assert reset.values("Part_Count", "Motor", "Batch_Lamp") == {
        "Part_Count": 0, "Motor": 1, "Batch_Lamp": 0}

    # the original is untouched by both branches
    assert running.values("Part_Count", "Motor") == {"Part_Count": 19, "Motor": 1}
