"""Build the client for a config section (the backend class comes from ``backends/registry.py``)."""

from __future__ import annotations

import hashlib
import threading

import numpy as np

from anomalygen.llm.backends.registry import make_backend
from anomalygen.llm.client import LLMClient


def get_client(
    config,
    *,
    rng: np.random.Generator | None = None,
    backoff_base_s: float = 0.5,
    backoff_max_s: float = 20.0,
) -> LLMClient:
    """The client for ``settings.llm``. ``rng`` adds jitter to retry backoff (none: deterministic delays)."""
    return LLMClient(
        config, make_backend(config), rng=rng, backoff_base_s=backoff_base_s, backoff_max_s=backoff_max_s
    )


_SHARED: dict[str, LLMClient] = {}
_SHARED_LOCK = threading.Lock()


def shared_client(config) -> LLMClient:
    """One client per process and configuration, reused across items (HTTP pool, cache connection, model).

    Why not ``functools.cache`` on ``config.model_dump_json()``: that JSON masks the API key as
    ``**********``, so a client rebuilt from it would send the mask. The key here hashes the secret
    instead. Take per-stage usage with ``client.reset_usage()``, since the client outlives a stage.
    """
    secret = config.api_key.get_secret_value() if config.api_key else ""
    key = config.model_dump_json() + hashlib.sha256(secret.encode()).hexdigest()
    with _SHARED_LOCK:
        if key not in _SHARED:
            _SHARED[key] = get_client(config)
        return _SHARED[key]
