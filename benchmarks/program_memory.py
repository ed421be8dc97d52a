"""Memory of compiled programs and of the benchmark process, for the benchmark tables.

``program_memory(compiled)``: XLA's own account of a compiled program
(``jax.stages.Compiled.memory_analysis()``): the arguments, the outputs and the
temporary buffers it allocates while it runs, in MB.  The program's peak is at most
``arguments + outputs + temporaries - aliased`` (XLA's buffer assignment packs the
temporaries into one block whose size is ``temp``; arguments donated to outputs are
counted once).  ``peak_rss_mb()``: the process's peak resident set so far (the
compiler's own memory included), from ``getrusage``.

Benchmarks are never tests.  Not for CI.
"""

from __future__ import annotations

import resource
import sys

MB = 1024.0 ** 2


def program_memory(compiled) -> dict:
    """``{"args", "out", "temp", "code", "peak"}`` in MB of a ``Compiled`` program (NaN
    where the backend gives no analysis)."""
    nan = float("nan")
    try:
        m = compiled.memory_analysis()
    except Exception:  # noqa: BLE001 - a backend without the analysis
        m = None
    if m is None:
        return dict(args=nan, out=nan, temp=nan, code=nan, peak=nan)
    args = m.argument_size_in_bytes / MB
    out = m.output_size_in_bytes / MB
    temp = m.temp_size_in_bytes / MB
    alias = getattr(m, "alias_size_in_bytes", 0) / MB
    return dict(args=args, out=out, temp=temp, code=m.generated_code_size_in_bytes / MB,
                peak=args + out + temp - alias)


def peak_rss_mb() -> float:
    """Peak resident set size of this process so far (MB)."""
    r = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return r / MB if sys.platform == "darwin" else r / 1024.0


def memory_cell(mem: dict) -> str:
    """``"peak (temp)"`` of :func:`program_memory` for a table cell, in MB."""
    return f"{mem['peak']:.1f} ({mem['temp']:.1f})"
