"""Sim-to-real gap diagnosis (work in progress)."""
from .effects import EFFECTS  # noqa: F401
