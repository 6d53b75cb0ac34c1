"""Plotting helpers (matplotlib, imported lazily by the callers)."""
