"""Matplotlib figures (Agg backend), saved atomically."""
