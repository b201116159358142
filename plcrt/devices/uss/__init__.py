"""The USS protocol library of Micro/WIN (:mod:`.library`), its telegrams
(:mod:`.telegram`) and simulated MicroMaster-style drives for the plant
(:mod:`.drive`); docs/uss.md."""
