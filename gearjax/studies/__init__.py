"""Research studies built on the chain."""
