"""Build the client for a config section; the only place that maps backend names to classes."""

from __future__ import annotations

import numpy as np

from anomalygen.errors import UserError
from anomalygen.llm.client import LLMClient

NO_BACKEND_HINT = (
    "no LLM configured: pass --backend openai|anthropic|llamacpp, set ANOMALYGEN_LLM__BACKEND, "
    'or set backend = "llamacpp" in the llm section of the config file'
)


def make_backend(config):
    if config.backend == "openai":
        from anomalygen.llm.backends.openai_backend import OpenAIBackend

        return OpenAIBackend(config)
    if config.backend == "anthropic":
        from anomalygen.llm.backends.anthropic_backend import AnthropicBackend

        return AnthropicBackend(config)
    if config.backend == "llamacpp":
        from anomalygen.llm.backends.llamacpp_backend import LlamaCppBackend

        return LlamaCppBackend(config)
    if config.backend == "none":
        raise UserError(NO_BACKEND_HINT)
    raise UserError(f"unknown LLM backend {config.backend!r} (choose openai, anthropic or llamacpp)")


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
