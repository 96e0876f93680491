"""The real CLI in a child process, and the bad files a user may hand it, for the one-line-error tests
(``tests/test_cli.py``, ``tests/brainstorm/test_bad_input.py``)."""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
from pathlib import Path


def run_cli(*args, env=None, cwd=None) -> subprocess.CompletedProcess:
    """``python -m anomalygen.cli ARGS``: the entry point a user runs, with its exit code and stderr."""
    full_env = {**os.environ, **(env or {})}
    return subprocess.run([sys.executable, "-m", "anomalygen.cli", *map(str, args)], capture_output=True, text=True,
                          env=full_env, cwd=cwd, timeout=120)


def one_error_line(result: subprocess.CompletedProcess, code: int = 2) -> str:
    """The single ``error:`` line of a failed command (no traceback, nothing else on stderr)."""
    assert result.returncode == code, result.stderr
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    return lines[0]


# name -> (how to make it under a folder, words its error must hold). Every file type a user can get
# wrong as text: the folder for a file, a missing path, a binary, Latin-1 and UTF-16 text, a
# 100,000-character line (a file with no line breaks).
BAD_FILES = {
    "folder": (lambda p: p.mkdir(), "a folder, not a"),
    "missing": (lambda p: None, "not found; check the path"),
    "binary": (lambda p: shutil.copyfile("/bin/ls", p), "a binary file, not a"),
    "latin1": (lambda p: p.write_bytes("Grand-m\u00e8re's pills are on the low table\n".encode("latin-1")),
               "line 1: not UTF-8 text (byte 0xe8 at column 8); save the"),
    "utf16": (lambda p: p.write_text("The kettle is on.\n", encoding="utf-16"), "is saved as UTF-16; save it as UTF-8"),
    "long_line": (lambda p: p.write_text("a" * 100_000 + "\n"), "line 1: "),
}


def make_bad_file(folder: Path, kind: str) -> tuple[Path, str]:
    """The bad file ``kind`` under ``folder`` and the words its one-line error must hold."""
    make, words = BAD_FILES[kind]
    path = folder / f"bad-{kind}"
    make(path)
    return path, words


def snapshot(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` with a hash of its bytes ({} when there is no folder)."""
    if not folder.exists():
        return {}
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}
