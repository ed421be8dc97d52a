"""Progress on stderr for long CLI work: named phases with elapsed time, and a bar.

Used only by the command layer (``gearjax/commands``); never inside traced code, and
library modules never print.  A :class:`Progress` shows

* a bar ``label [#####     ] k/n`` over the steps a command loops over in Python
  (flank sides, flanks, designs), advanced by :meth:`Progress.update`;
* a *phase* (:meth:`Progress.phase`, a context manager) around one long call -- a
  jitted solve, say -- with its name and the elapsed seconds.  While JAX traces or
  compiles inside the phase the line reads ``compiling (first run; cached afterwards)``
  instead of the phase name: the start and end of tracing, lowering and XLA
  compilation are reported by JAX's public event hooks (:mod:`jax.monitoring`,
  events under ``/jax/core/compile/``), so the switch needs nothing from the library.
  When the phase ends a permanent line ``label: NAME done in 12.3 s`` is left (with
  the compile time when JAX compiled).

On a terminal the line is redrawn in place (``\\r``) and a background thread ticks the
elapsed time four times a second (a compile blocks the main thread).  Elsewhere --
pipes, files, tests -- nothing is written, unless forced (``force=True`` or the
environment variable ``GEARJAX_PROGRESS=1``); forced output to a non-terminal is one
plain line per event (phase start, compile start/end, phase end, bar step), without
redrawing.  ``GEARJAX_PROGRESS=0`` silences it even on a terminal.
"""

from __future__ import annotations

import os
import shutil
import sys
import threading
import time
from contextlib import contextmanager

__all__ = ["Progress", "progress_enabled", "COMPILE_TEXT", "ENV_VAR"]

ENV_VAR = "GEARJAX_PROGRESS"
COMPILE_TEXT = "compiling (first run; cached afterwards)"
_COMPILE_EVENTS = "/jax/core/compile/"     # prefix of JAX's trace/lower/compile events
_SPIN = "|/-\\"


def _isatty(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):   # closed or not a file
        return False


def progress_enabled(stream=None, force: bool | None = None) -> bool:
    """Whether progress goes to ``stream`` (default ``sys.stderr``).

    ``force=True`` -> yes; else ``$GEARJAX_PROGRESS`` = ``1``/``true``/``yes``/``on`` -> yes,
    ``0``/``false``/``no``/``off`` -> no; else only when ``stream`` is a terminal.
    """
    if force:
        return True
    env = os.environ.get(ENV_VAR, "").strip().lower()
    if env in ("1", "true", "yes", "on", "force"):
        return True
    if env in ("0", "false", "no", "off"):
        return False
    return _isatty(sys.stderr if stream is None else stream)


class _CompileWatch:
    """Counts JAX trace/lower/compile events open right now (via jax.monitoring; the
    events of programs compiled side by side arrive from worker threads)."""

    def __init__(self, on_change):
        self.open = 0
        self.count = 0          # compile-pipeline steps finished
        self.seconds = 0.0      # their total duration (s); nested or overlapping steps once
        self._on_change = on_change
        self._mon = None
        self._lock = threading.Lock()

    def _start(self, event, value, **kw):
        if event.startswith(_COMPILE_EVENTS):
            with self._lock:
                self.open += 1
                first = self.open == 1
            if first:
                self._on_change()

    def _end(self, event, duration, **kw):
        if event.startswith(_COMPILE_EVENTS):
            with self._lock:
                self.count += 1
                if self.open <= 1:
                    self.seconds += float(duration)
                self.open = max(self.open - 1, 0)
                last = self.open == 0
            if last:
                self._on_change()

    def __enter__(self):
        try:
            import jax.monitoring as mon
            mon.register_scalar_listener(self._start)
            mon.register_event_duration_secs_listener(self._end)
            self._mon = mon
        except (ImportError, AttributeError):   # an older JAX: phases still show time
            self._mon = None
        return self

    def __exit__(self, *exc):
        if self._mon is not None:
            for unreg, cb in ((getattr(self._mon, "unregister_scalar_listener", None), self._start),
                              (getattr(self._mon, "unregister_event_duration_listener", None),
                               self._end)):
                if unreg is not None:
                    try:
                        unreg(cb)
                    except (ValueError, AssertionError, KeyError):
                        pass
        self.open = 0
        return False


class Progress:
    """Context manager: a bar over ``total`` steps plus named phases, on stderr.

    ``label``: what is being done (``"tca example:hft_8x43"``); ``enabled=False``
    silences it; ``force=True`` writes even to a non-terminal (see
    :func:`progress_enabled`); ``stream``: where to write (default ``sys.stderr`` at
    construction); ``interval``: seconds between redraws of a running phase on a
    terminal.
    """

    def __init__(self, total: int, label: str = "", enabled: bool = True,
                 force: bool | None = None, stream=None, interval: float = 0.25):
        self.total = max(int(total), 1)
        self.label = label
        self.stream = sys.stderr if stream is None else stream
        self.enabled = bool(enabled) and progress_enabled(self.stream, force)
        self.live = self.enabled and _isatty(self.stream)   # redraw in place + ticker
        self.interval = float(interval)
        self.k = 0
        self.t0 = time.perf_counter()
        self._phase = None          # (name, start time)
        self._watch = None
        self._tick = 0
        self._lock = threading.Lock()

    # -- output ---------------------------------------------------------------------
    def _write(self, text: str):
        try:
            self.stream.write(text)
            self.stream.flush()
        except (OSError, ValueError):   # closed pipe or stream: progress is optional
            self.enabled = self.live = False

    def _status(self) -> str:
        if self._phase is None:
            return ""
        name, t = self._phase
        busy = self._watch is not None and self._watch.open > 0
        return f"{name}: {COMPILE_TEXT}" if busy else name

    def _line(self) -> str:
        width = 30
        filled = int(width * self.k / self.total)
        bar = "#" * filled + " " * (width - filled)
        parts = [self.label] if self.label else []
        if self.total > 1:
            parts.append(f"[{bar}] {self.k}/{self.total}")
        st = self._status()
        if st:
            spin = _SPIN[self._tick % len(_SPIN)] if self.live else ""
            dt = time.perf_counter() - self._phase[1]
            parts.append(f"{spin} {st} {dt:5.1f}s".strip())
        else:
            parts.append(f"{time.perf_counter() - self.t0:5.1f}s")
        return " ".join(parts)

    def _draw(self):
        if not self.enabled:
            return
        with self._lock:
            if self.live:   # one terminal row: a wrapped line could not be redrawn
                cols = shutil.get_terminal_size((100, 24)).columns
                self._write("\r" + self._line()[:max(cols - 1, 20)] + "\x1b[K")
            else:
                self._write(self._line() + "\n")

    def _finish_line(self, text: str):
        if not self.enabled:
            return
        with self._lock:
            self._write(("\r" + text + "\x1b[K\n") if self.live else (text + "\n"))

    # -- public API -----------------------------------------------------------------
    def __enter__(self):
        if self.live:       # a log gets its first line from a phase or a step
            self._draw()
        return self

    def update(self, n: int = 1):
        """Advance the bar by ``n`` steps (clipped at ``total``)."""
        self.k = min(self.k + int(n), self.total)
        self._draw()

    @contextmanager
    def phase(self, name: str):
        """Show ``name`` and its elapsed time while the ``with`` block runs; the line
        reads ``compiling (first run; cached afterwards)`` while JAX compiles."""
        if not self.enabled:
            yield self
            return
        self._phase = (name, time.perf_counter())
        stop = threading.Event()
        ticker = None
        said = []

        def on_compile_change():
            # a terminal line follows every switch; a log gets the first "compiling" only
            if self.live or (watch.open and not said):
                said.append(1)
                self._draw()

        with _CompileWatch(on_compile_change) as watch:
            self._watch = watch
            self._draw()
            if self.live:
                def tick():
                    while not stop.wait(self.interval):
                        self._tick += 1
                        self._draw()
                ticker = threading.Thread(target=tick, name="gearjax-progress", daemon=True)
                ticker.start()
            ok = False
            try:
                yield self
                ok = True
            finally:
                stop.set()
                if ticker is not None:
                    ticker.join()
                dt = time.perf_counter() - self._phase[1]
                comp = (f" (compiling {watch.seconds:.1f} s)" if watch.count else "")
                head = f"{self.label}: " if self.label else ""
                self._finish_line(f"{head}{name} {'done' if ok else 'stopped'} in {dt:.1f} s{comp}")
                self._watch = None
                self._phase = None

    def __exit__(self, *exc):
        if self.live:
            with self._lock:
                self._write("\r\x1b[K")      # the bar line goes; phase lines stay
        return False
