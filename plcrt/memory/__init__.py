"""Memory model: CPU area sizes and the byte-array memory image."""

from .cpu import CPU_MODELS, DEFAULT_CPU, CpuModel, cpu_model
from .image import MemoryImage, Snapshot

__all__ = ["CPU_MODELS", "DEFAULT_CPU", "CpuModel", "cpu_model", "MemoryImage", "Snapshot"]
