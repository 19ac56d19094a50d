# SPDX-License-Identifier: Apache-2.0
"""Running one library call: its own context, a worker thread, progress,
cancellation and Ctrl-C.

The call runs in a worker thread while the calling thread waits on it in
short join() slices, so that a KeyboardInterrupt reaches the caller at once
even though the library is busy in C. Then the progress callback answers 0
from its next call on, the library stops with VP_ERR_CANCELLED and frees
what it made, the worker is joined, and the KeyboardInterrupt goes on up.
"""
import ctypes
import numbers
import threading

from . import _errors
from . import _lib
from ._lib import lib

_SLICE = 0.05  # seconds between looks at a pending KeyboardInterrupt


def check_threads(threads):
    """threads=None or 0: all cores; else a whole number in 1..256."""
    if threads is None:
        return 0
    if isinstance(threads, bool) or not isinstance(threads, numbers.Integral):
        raise TypeError("threads must be a whole number (or None: all cores), not %r"
                        % (threads,))
    threads = int(threads)
    if not 0 <= threads <= 256:
        raise ValueError("threads must be in 1..256 (or 0/None: all cores), not %d" % threads)
    return threads


_UNITS = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}


def check_max_memory(max_memory):
    """max_memory=None or 0: physical memory; bytes as a whole number, or a
    size such as "8G" or "500M" (as the command line's --max-memory)."""
    if max_memory is None:
        return 0
    if isinstance(max_memory, str):
        text = max_memory.strip().upper()
        if text.endswith("B") and len(text) > 1 and text[-2] in "KMGT":
            text = text[:-1]
        unit = text[-1:] if text[-1:] in "KMGT" else ""
        try:
            value = float(text[:len(text) - len(unit)]) * _UNITS[unit]
        except ValueError:
            value = -1.0
        if not (0 < value < 1.8e19):
            raise ValueError("max_memory must be a size such as '8G' or '500M', or bytes, not %r"
                             % (max_memory,))
        return int(value)
    if isinstance(max_memory, bool) or not isinstance(max_memory, numbers.Integral):
        raise TypeError("max_memory must be bytes (a whole number) or a size such as '8G', "
                        "not %r" % (max_memory,))
    if not 0 <= max_memory < 1 << 64:
        raise ValueError("max_memory must be >= 0 bytes, not %d" % max_memory)
    return int(max_memory)


def check_progress(progress):
    if progress is not None and not callable(progress):
        raise TypeError("progress must be a callable progress(fraction, stage) or None, not %r"
                        % (progress,))
    return progress


class _State:
    def __init__(self, progress, watch):
        self.progress = progress
        self.watch = watch
        self.cancel = False       # answer 0 from now on
        self.user_cancelled = False
        self.error = None         # what the user's callback raised

    def callback(self, user, fraction, stage):
        # Runs in a library thread, under the GIL (ctypes takes it). Nothing
        # may escape: an exception here would be printed and swallowed by
        # ctypes, and the call would go on.
        try:
            if self.cancel:
                return 0
            for c in self.watch:
                if c._callback_error is not None:
                    self.cancel = True
                    return 0
            if self.progress is not None:
                answer = self.progress(fraction, stage.decode("utf-8", "replace") if stage else "")
                if answer is not None and not answer:
                    self.user_cancelled = True
                    self.cancel = True
                    return 0
            return 1
        except BaseException as e:  # noqa: B902 -- even SystemExit stops the call
            self.error = e
            self.cancel = True
            return 0


def run(call, threads=None, max_memory=None, progress=None, watch=()):
    """Runs call(ctx) -> vp_result on a fresh context in a worker thread.
    Returns None on VP_OK; raises the vdbpack.Error subclass of the result
    with the context's message, the progress callback's own exception,
    CancelledError when it asked to stop, or KeyboardInterrupt when one
    came while waiting. `watch`: containers whose Python callbacks may have
    failed (their failure cancels the call and is raised)."""
    threads = check_threads(threads)
    max_memory = check_max_memory(max_memory)
    state = _State(check_progress(progress), tuple(watch))
    ctx = ctypes.c_void_p()
    if lib.vp_context_create(ctypes.byref(ctx)) != _lib.VP_OK:
        raise _errors.OutOfMemoryError("vdbpack: cannot create a context", "VP_ERR_OUT_OF_MEMORY")
    try:
        if threads:
            lib.vp_context_set_threads(ctx, threads)
        if max_memory:
            lib.vp_context_set_max_memory(ctx, max_memory)
        cb = _lib.PROGRESS_FN(state.callback)  # referenced until the call has returned
        lib.vp_context_set_progress(ctx, cb, None)
        box = {}
        # The caller waits on a lock that the worker releases when the call
        # is over, and on box["done"] (set first): not on Thread.join, which
        # a KeyboardInterrupt can leave believing that a running thread has
        # ended (CPython 3.11, bpo-45274's fix in _wait_for_tstate_lock),
        # and the context would then be destroyed under the library.
        over = threading.Lock()
        over.acquire()

        def work():
            try:
                box["result"] = call(ctx)
            except BaseException as e:  # a bug in the argument marshalling
                box["error"] = e
            finally:
                box["done"] = True
                over.release()

        worker = threading.Thread(target=work, name="vdbpack-call", daemon=True)
        worker.start()
        interrupt = None
        while not box.get("done"):
            try:
                over.acquire(timeout=_SLICE)
            except KeyboardInterrupt as e:
                # keep waiting: the library stops at its next progress report
                interrupt = interrupt or e
                state.cancel = True
        message = (lib.vp_context_message(ctx) or b"").decode("utf-8", "replace")
    finally:
        lib.vp_context_destroy(ctx)
    if interrupt is not None:
        raise interrupt
    if "error" in box:
        raise box["error"]
    if state.error is not None:
        raise state.error
    for c in state.watch:
        if c._callback_error is not None:
            e, c._callback_error = c._callback_error, None
            raise e
    result = box.get("result", _lib.VP_ERR_INTERNAL)
    if state.user_cancelled:
        raise _errors.CancelledError(message or "cancelled by the progress callback",
                                     "VP_ERR_CANCELLED")
    if result != _lib.VP_OK:
        raise error(result, message)
    return None


def error(result, message):
    """The exception for a vp_result and its message."""
    cls = _errors.BY_RESULT.get(result, _errors.InternalError)
    name = lib.vp_result_name(result).decode()
    return cls(message or name, name)


def quick(call):
    """A short call (no progress, no thread) on a fresh context: parsing,
    small queries. Returns None on VP_OK, else raises."""
    ctx = ctypes.c_void_p()
    if lib.vp_context_create(ctypes.byref(ctx)) != _lib.VP_OK:
        raise _errors.OutOfMemoryError("vdbpack: cannot create a context", "VP_ERR_OUT_OF_MEMORY")
    try:
        r = call(ctx)
        message = (lib.vp_context_message(ctx) or b"").decode("utf-8", "replace")
    finally:
        lib.vp_context_destroy(ctx)
    if r != _lib.VP_OK:
        raise error(r, message)
