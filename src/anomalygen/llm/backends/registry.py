"""Which backend class serves a config section: the only place that maps backend names to classes.

Below both the client (which rebuilds its backend when unpickled in a worker) and the factory (which
builds clients), so neither has to import the other.
"""

from __future__ import annotations

from anomalygen.errors import UserError

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
