"""Matplotlib figures (Agg backend), saved atomically."""


def headless() -> None:
    """Select matplotlib's Agg backend (files, no display) unless a backend was already
    chosen -- a notebook kernel's inline backend, ``MPLBACKEND``, ``matplotlib.use`` by
    the user: the library never replaces a backend someone chose (forcing Agg on
    import hid every figure of a notebook that imported a plot module)."""
    import matplotlib
    chosen = getattr(matplotlib.rcParams, "_get_backend_or_none", lambda: None)()
    if chosen is None:
        matplotlib.use("Agg")
