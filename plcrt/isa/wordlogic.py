"""Instruction family: word logic, shifts and rotates (filled in by its table)."""

from __future__ import annotations
