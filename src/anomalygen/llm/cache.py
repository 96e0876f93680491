"""Content-addressed SQLite cache of raw model replies.

Why raw replies per request (not final objects): a repair conversation is a sequence of requests, and
caching each one makes a re-run replay the whole conversation without touching the model, while a
changed prompt, schema or sampling parameter naturally misses. The key is a SHA-256 of canonical JSON
of everything that determines the reply; API keys and endpoints are never part of it or stored.

Several processes (the spawn pool) share the file: WAL mode, a busy timeout and one short
transaction per read or write.
"""

from __future__ import annotations

import hashlib
import json
import os
import sqlite3
import threading
import time
from pathlib import Path
from typing import Any

DEFAULT_CACHE_PATH = Path("~/.cache/anomalygen/llm.sqlite")


def default_cache_path() -> Path:
    return DEFAULT_CACHE_PATH.expanduser()


def cache_key(parts: dict[str, Any]) -> str:
    blob = json.dumps(parts, sort_keys=True, separators=(",", ":"), ensure_ascii=False, default=str)
    return hashlib.sha256(blob.encode("utf-8")).hexdigest()


class ReplyCache:
    """``get(key) -> (text, prompt_tokens, completion_tokens) | None`` and ``put``; thread-safe."""

    def __init__(self, path: str | Path | None):
        self.path = Path(path).expanduser() if path else default_cache_path()
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._local = threading.local()
        with self._connect() as con:
            con.execute(
                "CREATE TABLE IF NOT EXISTS replies (key TEXT PRIMARY KEY, text TEXT NOT NULL,"
                " prompt_tokens INTEGER, completion_tokens INTEGER, created REAL)"
            )

    def _connect(self) -> sqlite3.Connection:
        con = getattr(self._local, "con", None)
        if con is None or getattr(self._local, "pid", None) != os.getpid():
            con = sqlite3.connect(self.path, timeout=30.0, isolation_level=None)
            con.execute("PRAGMA journal_mode=WAL")
            con.execute("PRAGMA synchronous=NORMAL")
            con.execute("PRAGMA busy_timeout=30000")
            self._local.con = con
            self._local.pid = os.getpid()
        return con

    def get(self, key: str) -> tuple[str, int, int] | None:
        row = (
            self._connect()
            .execute("SELECT text, prompt_tokens, completion_tokens FROM replies WHERE key = ?", (key,))
            .fetchone()
        )
        return None if row is None else (row[0], int(row[1] or 0), int(row[2] or 0))

    def put(self, key: str, text: str, prompt_tokens: int, completion_tokens: int) -> None:
        self._connect().execute(
            "INSERT OR REPLACE INTO replies (key, text, prompt_tokens, completion_tokens, created) VALUES (?, ?, ?, ?, ?)",
            (key, text, prompt_tokens, completion_tokens, time.time()),
        )

    def __len__(self) -> int:
        return int(self._connect().execute("SELECT COUNT(*) FROM replies").fetchone()[0])
