"""The progress callback between veil_render and Python.

The rule: veil calls progress(stage, done) with stage one of "inject",
"propagate", "volumetric", "render", "spread" and done in [0, 1], the share
of that stage done. Returning False (exactly False) cancels the render:
veil.render raises veil.Cancelled. Any other return value (None, True, a
number) lets it go on. An exception raised by the callback cancels it too,
and render() raises that exception once veil_render has returned; so does
Ctrl-C, which Python delivers while a callback runs.
"""

import contextlib
import signal
import sys
import threading

from ._lib import PROGRESS_CALLBACK

STAGES = ("inject", "propagate", "volumetric", "render", "spread")


class Bridge:
    """Wraps a Python callable (or None) as the C callback; keeps what it raised."""

    def __init__(self, fn):
        self.fn = fn
        self.raised = None  # the exception the callable raised (it cancelled the render)
        self.cancelled = False
        self.interrupted = False  # Ctrl-C while veil rendered (see interrupts())
        self.c_callback = PROGRESS_CALLBACK(self._call)  # referenced here: alive while the render runs

    def _call(self, user, stage, done):
        if self.raised is not None or self.cancelled or self.interrupted:
            return 1
        try:
            if self.fn is not None and self.fn(stage.decode() if stage else "", float(done)) is False:
                self.cancelled = True
        except BaseException as e:  # KeyboardInterrupt included: it cancels the render
            self.raised = e
        return 1 if self.raised is not None or self.cancelled or self.interrupted else 0

    @contextlib.contextmanager
    def interrupts(self):
        """While veil renders on the main thread, Ctrl-C sets a flag that the next callback turns
        into a cancel (Python runs signal handlers only between its own bytecodes, so a
        KeyboardInterrupt raised inside the ctypes callback could be lost); render() raises
        KeyboardInterrupt once veil_render has returned. A handler the program set is left alone."""
        if (threading.current_thread() is not threading.main_thread()
                or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
            yield
            return

        def on_sigint(signum, frame):
            self.interrupted = True

        signal.signal(signal.SIGINT, on_sigint)
        try:
            yield
        finally:
            signal.signal(signal.SIGINT, signal.default_int_handler)


class TqdmProgress:
    """A tqdm bar per stage (progress="tqdm" or progress=True with tqdm installed)."""

    def __init__(self, tqdm, desc=""):
        self.tqdm = tqdm
        self.desc = desc
        self.stage = None
        self.bar = None

    def __call__(self, stage, done):
        if stage != self.stage:
            self.close()
            self.stage = stage
            self.bar = self.tqdm(total=1000, desc=(self.desc + stage).strip(), leave=False,
                                 bar_format="{desc:>16} {percentage:3.0f}%|{bar}| {elapsed}")
        n = int(round(min(max(done, 0.0), 1.0) * 1000))
        if n > self.bar.n:
            self.bar.update(n - self.bar.n)
        return None

    def close(self):
        if self.bar is not None:
            self.bar.close()
            self.bar = None


class TextProgress:
    """One line per stage on stderr (progress=True without tqdm)."""

    def __init__(self, desc=""):
        self.desc = desc
        self.stage = None

    def __call__(self, stage, done):
        if stage != self.stage:
            self.stage = stage
            sys.stderr.write("veil: %s%s\n" % (self.desc, stage))
            sys.stderr.flush()
        return None

    def close(self):
        pass


def check(progress):
    """Raises for a progress argument render() cannot use (before any work)."""
    if progress is None or progress is False or progress is True or progress == "tqdm":
        return
    if isinstance(progress, str):
        raise ValueError("progress: expected a callable(stage, done), True, 'tqdm' or None, got %r" % progress)
    if not callable(progress):
        raise TypeError("progress: expected a callable(stage, done), True, 'tqdm' or None, got %s"
                        % type(progress).__name__)


def resolve(progress, desc=""):
    """(the callable, or None; a close() for a bar or None) for render's progress argument."""
    if progress is None or progress is False:
        return None, None
    if progress is True or progress == "tqdm":
        try:
            from tqdm.auto import tqdm
        except ImportError:
            if progress == "tqdm":
                raise ImportError("progress='tqdm' needs the tqdm package (apt install python3-tqdm, or "
                                  "pip install tqdm); progress=True falls back to lines on stderr") from None
            bar = TextProgress(desc)
            return bar, bar.close
        bar = TqdmProgress(tqdm, desc)
        return bar, bar.close
    check(progress)
    return progress, None
