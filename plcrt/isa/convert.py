"""Instruction family: conversions (filled in by its table)."""

from __future__ import annotations
