"""A real, scripted OpenAI-compatible (and Anthropic-compatible) HTTP server for tests.

Why a real server rather than a mocked client: the LLM layer's retries, timeouts, concurrency limits
and SDK request shapes are only exercised when bytes actually cross a socket. The server listens on
127.0.0.1 on a free port, runs in a daemon thread and stops when the ``with`` block ends.

Usage::

    from tests.support.openai_server import ScriptedOpenAIServer, text, status, hang

    with ScriptedOpenAIServer([status(429), text('{"a": 1}')]) as srv:
        cfg = LLMConfig(backend="openai", base_url=srv.base_url, model="m", api_key="sk-test")
        ...
        assert len(srv.requests) == 2

``responder`` is either a list of replies consumed in order (the last one repeats forever) or a
callable ``responder(request_json) -> Reply`` (it may inspect ``request_json["messages"]``; it is
called from server threads, so keep shared state thread-safe).

Endpoints:
- ``POST /v1/chat/completions`` (non-streaming) — ``text`` replies become a ``chat.completion``.
- ``POST /v1/messages`` (Anthropic Messages API) — ``text`` becomes a text block, ``tool_use`` a
  tool_use block.
- ``GET /v1/models`` — a one-model list.

Every POST body is appended to ``requests`` (and its headers to ``headers``) before the reply is
chosen, so a test can assert what the client sent, including the repair message.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any


@dataclass(frozen=True)
class Reply:
    """One scripted answer. Build it with ``text``, ``status``, ``hang`` or ``tool_use``."""

    kind: str  # "text" | "status" | "hang" | "tool_use"
    content: str = ""
    code: int = 200
    body: str = ""
    seconds: float = 0.0
    then: Reply | None = None
    tool_input: dict[str, Any] = field(default_factory=dict)
    tool_name: str | None = None
    prompt_tokens: int = 11
    completion_tokens: int = 7


def text(content: str, *, prompt_tokens: int = 11, completion_tokens: int = 7) -> Reply:
    """A normal completion whose message content is ``content`` (with the given usage counts)."""
    return Reply("text", content=content, prompt_tokens=prompt_tokens, completion_tokens=completion_tokens)


def status(code: int, body: str = "") -> Reply:
    """An HTTP error (e.g. 429, 500, 400) with an OpenAI-style error body unless ``body`` is given."""
    return Reply("status", code=code, body=body)


def hang(seconds: float, then: Reply | None = None) -> Reply:
    """Sleep ``seconds`` (interrupted when the server stops) and then answer ``then`` (default: "{}")."""
    return Reply("hang", seconds=seconds, then=then)


def tool_use(tool_input: dict[str, Any], name: str | None = None) -> Reply:
    """Anthropic only: a tool_use block with ``tool_input`` (tool name defaults to the forced tool)."""
    return Reply("tool_use", tool_input=tool_input, tool_name=name)


Responder = Callable[[dict[str, Any]], Reply] | list[Reply]


class ScriptedOpenAIServer:
    """Context manager running the scripted server; see the module docstring."""

    MAX_BODY = 64 * 1024 * 1024  # refuse absurd bodies rather than read forever

    def __init__(self, responder: Responder, *, model: str = "scripted-model"):
        if isinstance(responder, list) and not responder:
            raise ValueError("a reply list needs at least one reply")
        self._responder = responder
        self._model = model
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._index = 0
        self.requests: list[dict[str, Any]] = []
        self.headers: list[dict[str, str]] = []
        self.paths: list[str] = []
        self._server: ThreadingHTTPServer | None = None
        self._thread: threading.Thread | None = None
        self.base_url = ""
        self.port = 0

    # -- lifecycle
    def __enter__(self) -> ScriptedOpenAIServer:
        handler = _make_handler(self)
        self._server = ThreadingHTTPServer(("127.0.0.1", 0), handler)
        self._server.daemon_threads = True
        self.port = self._server.server_address[1]
        self.base_url = f"http://127.0.0.1:{self.port}/v1"
        self._thread = threading.Thread(
            target=self._server.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True
        )
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()  # wakes up hanging handlers
        if self._server is not None:
            self._server.shutdown()
            self._server.server_close()
        if self._thread is not None:
            self._thread.join(timeout=5)

    @property
    def root_url(self) -> str:
        """The URL without ``/v1`` (the Anthropic SDK appends ``/v1/messages`` itself)."""
        return f"http://127.0.0.1:{self.port}"

    # -- scripting
    def _next_reply(self, body: dict[str, Any]) -> Reply:
        if callable(self._responder):
            return self._responder(body)
        with self._lock:
            reply = self._responder[min(self._index, len(self._responder) - 1)]
            self._index += 1
        return reply

    def _record(self, path: str, headers: dict[str, str], body: dict[str, Any]) -> None:
        with self._lock:
            self.paths.append(path)
            self.headers.append(headers)
            self.requests.append(body)

    def _wait(self, seconds: float) -> None:
        self._stop.wait(timeout=max(0.0, seconds))


def _make_handler(srv: ScriptedOpenAIServer) -> type[BaseHTTPRequestHandler]:
    class Handler(BaseHTTPRequestHandler):
        protocol_version = "HTTP/1.1"
        disable_nagle_algorithm = (
            True  # headers and body go out in two writes: avoid the 40 ms delayed-ACK stall
        )

        def log_message(self, format: str, *args: Any) -> None:  # keep test output quiet
            return

        def _send(self, code: int, payload: Any, *, raw: str | None = None) -> None:
            data = (raw if raw is not None else json.dumps(payload)).encode("utf-8")
            try:
                self.send_response(code)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(data)))
                if code == 429:
                    self.send_header("Retry-After", "0")
                self.end_headers()
                self.wfile.write(data)
            except (BrokenPipeError, ConnectionResetError):
                pass  # the client gave up (timeout); nothing to do

        def do_GET(self) -> None:
            if self.path.rstrip("/").endswith("/models"):
                self._send(
                    200,
                    {"object": "list", "data": [{"id": srv._model, "object": "model", "owned_by": "tests"}]},
                )
            else:
                self._send(404, {"error": {"message": f"no route {self.path}", "type": "not_found"}})

        def do_POST(self) -> None:
            length = int(self.headers.get("Content-Length") or 0)
            if length > srv.MAX_BODY:
                self._send(413, {"error": {"message": "body too large"}})
                return
            raw = self.rfile.read(length) if length else b""
            try:
                body = json.loads(raw or b"{}")
            except json.JSONDecodeError:
                self._send(400, {"error": {"message": "invalid JSON body", "type": "invalid_request_error"}})
                return
            path = self.path.split("?")[0].rstrip("/")
            srv._record(path, {k.lower(): v for k, v in self.headers.items()}, body)
            if path.endswith("/chat/completions"):
                flavour = "openai"
            elif path.endswith("/messages"):
                flavour = "anthropic"
            else:
                self._send(404, {"error": {"message": f"no route {self.path}", "type": "not_found"}})
                return
            reply = srv._next_reply(body)
            for _ in range(8):  # hang → then → ... bounded
                if reply.kind != "hang":
                    break
                srv._wait(reply.seconds)
                if srv._stop.is_set():
                    return
                reply = reply.then or text("{}")
            self._answer(flavour, body, reply)

        def _answer(self, flavour: str, body: dict[str, Any], reply: Reply) -> None:
            if reply.kind == "status":
                if reply.body:
                    self._send(reply.code, None, raw=reply.body)
                else:
                    kind = "rate_limit_error" if reply.code == 429 else "api_error"
                    err = {"message": f"scripted status {reply.code}", "type": kind}
                    payload = {"type": "error", "error": err} if flavour == "anthropic" else {"error": err}
                    self._send(reply.code, payload)
                return
            model = body.get("model") or srv._model
            if flavour == "openai":
                self._send(200, _chat_completion(model, reply))
            else:
                self._send(200, _anthropic_message(model, body, reply))

    return Handler


def _chat_completion(model: str, reply: Reply) -> dict[str, Any]:
    content = reply.content if reply.kind == "text" else json.dumps(reply.tool_input)
    return {
        "id": f"chatcmpl-{time.monotonic_ns()}",
        "object": "chat.completion",
        "created": int(time.time()),
        "model": model,
        "choices": [
            {
                "index": 0,
                "message": {"role": "assistant", "content": content},
                "finish_reason": "stop",
                "logprobs": None,
            }
        ],
        "usage": {
            "prompt_tokens": reply.prompt_tokens,
            "completion_tokens": reply.completion_tokens,
            "total_tokens": reply.prompt_tokens + reply.completion_tokens,
        },
    }


def _anthropic_message(model: str, body: dict[str, Any], reply: Reply) -> dict[str, Any]:
    if reply.kind == "tool_use":
        forced = (body.get("tool_choice") or {}).get("name")
        tools = body.get("tools") or [{}]
        name = reply.tool_name or forced or tools[0].get("name", "tool")
        block: dict[str, Any] = {
            "type": "tool_use",
            "id": f"toolu_{time.monotonic_ns()}",
            "name": name,
            "input": reply.tool_input,
        }
        stop = "tool_use"
    else:
        block = {"type": "text", "text": reply.content}
        stop = "end_turn"
    return {
        "id": f"msg_{time.monotonic_ns()}",
        "type": "message",
        "role": "assistant",
        "model": model,
        "content": [block],
        "stop_reason": stop,
        "stop_sequence": None,
        "usage": {"input_tokens": reply.prompt_tokens, "output_tokens": reply.completion_tokens},
    }
