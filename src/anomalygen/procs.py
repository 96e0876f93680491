"""Child processes that never outlive their parent.

Why: a spawned worker blocks in its own work and never notices that the process which started it is
gone. After a ``kill -9`` of ``anomalygen run`` during learn, two workers kept running for a quarter
of an hour. Every worker and isolation child calls :func:`die_with_parent` first: on Linux the kernel
sends it SIGKILL when its parent dies (``prctl(PR_SET_PDEATHSIG)``), and a watchdog thread checks the
parent's pid as a fallback (other systems, or a parent that died before the call took effect).

``PR_SET_PDEATHSIG`` fires when the *thread* that created the child exits, so it is set only for
children started from their parent's main thread (pass ``from_main_thread``); the watchdog covers
the rest.

Workers also send anything a library prints on stdout to stderr: stdout belongs to the parent's
machine-readable output (``--json``), and a worker has nothing of its own to say there.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys
import threading
import time

PR_SET_PDEATHSIG = 1  # linux/prctl.h
WATCH_S = 0.5  # how often the watchdog looks at the parent's pid (seconds)


def die_with_parent(parent_pid: int, from_main_thread: bool = True) -> None:
    """End this process when ``parent_pid`` is no longer its parent (call first thing in a child)."""
    quiet_stdout()
    if from_main_thread and sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        except (OSError, AttributeError):  # no prctl: the watchdog alone
            pass
    if os.getppid() != parent_pid:  # the parent died before the kernel could be told
        os._exit(1)
    threading.Thread(target=_watch, args=(parent_pid,), daemon=True, name="die-with-parent").start()


def end_with_parent() -> None:
    """``preexec_fn`` for a stage a script starts with ``subprocess``: the kernel ends it (SIGTERM, so
    its own pool workers go with it) when the script dies. A benchmark killed mid-run otherwise left
    its ``anomalygen learn`` running for twenty minutes beside the next measurement."""
    if sys.platform.startswith("linux"):
        try:
            ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
        except (OSError, AttributeError):
            pass


def _watch(parent_pid: int) -> None:
    while True:
        time.sleep(WATCH_S)
        if os.getppid() != parent_pid:
            os.kill(os.getpid(), signal.SIGKILL)


def quiet_stdout() -> None:
    """Route this process's stdout (Python's and the C library's) to stderr."""
    try:
        sys.stdout.flush()
        os.dup2(2, 1)
    except (OSError, ValueError, AttributeError):  # no such descriptors (an embedded interpreter)
        return
    sys.stdout = sys.stderr


def child_pool(workers: int):
    """A spawn process pool whose workers die with this process (spawn, not fork: torch and MuJoCo's
    renderer do not survive a fork of a threaded parent)."""
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    return ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn"), initializer=die_with_parent,
                               initargs=(os.getpid(), threading.current_thread() is threading.main_thread()))
