"""Start, watch and restart a llama.cpp server in a child process (see ``gguf_server``).

The parent keeps the child's stdin open; closing it (or the parent dying) makes the child exit, so no
server outlives the run. The child's log goes to a temporary file whose tail is quoted when the
server fails to start or dies.
"""

from __future__ import annotations

import atexit
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from anomalygen.errors import UserError

START_TIMEOUT_S = 120.0  # loading a multi-GB GGUF from a cold disk on 2 cores
LOG_TAIL_CHARS = 600


class ServerStartError(UserError):
    """The llama.cpp server did not come up (bad model file, out of memory, crash at load)."""


def describe_exit(returncode: int | None) -> str:
    """'killed by SIGSEGV' / 'exited with code 2' / 'still running'."""
    if returncode is None:
        return "still running"
    if returncode < 0:
        try:
            return f"killed by {signal.Signals(-returncode).name}"
        except ValueError:
            return f"killed by signal {-returncode}"
    return f"exited with code {returncode}"


def default_threads() -> int:
    """The cores this process may use, less one (the pipeline and the simulator keep a core), 1 to 4.

    Why not every core: llama.cpp's worker threads wait for each other in spin barriers, so one
    thread pre-empted by another busy process stalls them all. On a 2-core machine beside a second
    busy process, two threads ran the tiny model's test requests many times slower than one.
    """
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # not Linux
        cores = os.cpu_count() or 1
    return max(1, min(4, cores - 1))


class LocalServer:
    """One ``gguf_server`` child process serving ``model`` on 127.0.0.1."""

    def __init__(self, model: Path, *, n_ctx: int, threads: int | None = None):
        self.model = Path(model)
        self.n_ctx = n_ctx
        self.threads = threads or default_threads()
        self.address: str | None = None
        self.starts = 0
        self._proc: subprocess.Popen | None = None
        self._log_path: Path | None = None
        self._lock = threading.Lock()
        atexit.register(self.stop)

    @property
    def pid(self) -> int | None:
        return self._proc.pid if self._proc is not None else None

    @property
    def running(self) -> bool:
        return self._proc is not None and self._proc.poll() is None

    @property
    def returncode(self) -> int | None:
        return self._proc.poll() if self._proc is not None else None

    def died(self, grace_s: float = 2.0) -> bool:
        """Whether the child has exited, waiting up to ``grace_s`` for it.

        Why wait: a killed process drops its sockets before its exit status can be read, so a
        request can see the connection fail while ``poll()`` still says running.
        """
        if self._proc is None:
            return True
        try:
            self._proc.wait(timeout=grace_s)
        except subprocess.TimeoutExpired:
            return False
        return True

    def ensure_running(self) -> str:
        """The base address of a live server, starting one if there is none (thread-safe)."""
        with self._lock:
            if not self.running:
                self._start()
            assert self.address is not None
            return self.address

    def log_tail(self) -> str:
        """The last lines of the child's log, on one line (for error messages)."""
        if self._log_path is None or not self._log_path.is_file():
            return ""
        text = self._log_path.read_text(errors="replace")[-LOG_TAIL_CHARS:]
        lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
        return " | ".join(lines[-4:])

    def stop(self) -> None:
        """End the child (stdin closed, then SIGTERM, then SIGKILL) and remove its log."""
        proc, self._proc = self._proc, None
        self.address = None
        if proc is not None:
            if proc.stdin is not None:
                try:
                    proc.stdin.close()
                except OSError:
                    pass
            try:
                proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                proc.terminate()
                try:
                    proc.wait(timeout=5)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()
        if self._log_path is not None:
            self._log_path.unlink(missing_ok=True)
            self._log_path = None

    # ------------------------------------------------------------------ internals
    def _start(self) -> None:
        self.stop()
        fd, log_name = tempfile.mkstemp(prefix="anomalygen-llamacpp-", suffix=".log")
        self._log_path = Path(log_name)
        cmd = [
            sys.executable, "-m", "anomalygen.llm.gguf_server",
            "--model", str(self.model), "--n-ctx", str(self.n_ctx), "--threads", str(self.threads),
        ]  # fmt: skip
        with os.fdopen(fd, "wb") as log:
            self._proc = subprocess.Popen(
                cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=log, start_new_session=True
            )
        self.starts += 1
        self.address = self._await_ready(self._proc)

    def _await_ready(self, proc: subprocess.Popen) -> str:
        """Read the child's ``READY <address>`` line, or fail with its exit status and log tail."""
        assert proc.stdout is not None
        line: list[str] = []
        reader = threading.Thread(target=lambda: line.append(proc.stdout.readline().decode()), daemon=True)
        reader.start()
        deadline = time.monotonic() + START_TIMEOUT_S
        while reader.is_alive() and time.monotonic() < deadline:
            reader.join(timeout=0.2)
        words = line[0].split() if line else []
        if len(words) == 2 and words[0] == "READY":
            return words[1]
        if not reader.is_alive():  # stdout closed: the child is exiting; let its status be read
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                pass
        status = describe_exit(proc.poll())
        tail = self.log_tail()
        self.stop()
        reason = "did not start" if reader.is_alive() else f"did not start ({status})"
        raise ServerStartError(
            f"the llama.cpp server for {self.model.name} {reason}" + (f": {tail}" if tail else "")
        )
