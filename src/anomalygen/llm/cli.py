"""``anomalygen llm ping|ask``: talk to the configured LLM directly.

Why: before a long brainstorm or detection run, a user wants to see that the endpoint answers and that
structured output works for a given schema. ``ask --schema TaskProposal`` runs exactly the path the
stages use (schema instruction, validation, repair, cache) and prints the validated object.
Imports stay light: SDKs load only when a command runs.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import Annotated, Any

import typer

from anomalygen.errors import UserError

app = typer.Typer(
    help="Talk to the configured LLM: ping, ask.", no_args_is_help=True, pretty_exceptions_enable=False
)

ConfigOpt = Annotated[Path | None, typer.Option("--config", "-c", help="TOML config file.")]
BackendOpt = Annotated[str | None, typer.Option("--backend", help="openai, anthropic or llamacpp.")]
ModelOpt = Annotated[str | None, typer.Option("--model", help="Model name, or a GGUF path for llamacpp.")]
BaseUrlOpt = Annotated[
    str | None, typer.Option("--base-url", help="OpenAI-compatible endpoint, e.g. http://localhost:8000/v1.")
]
JsonOpt = Annotated[bool, typer.Option("--json", help="Machine-readable JSON output.")]
NoCacheOpt = Annotated[bool, typer.Option("--no-cache", help="Bypass the LLM response cache.")]


def llm_settings(
    config: Path | None,
    backend: str | None,
    model: str | None,
    base_url: str | None,
    no_cache: bool = False,
    **more: Any,
):
    """Settings with CLI overrides on top of TOML and env (same rules as the stage commands)."""
    from anomalygen.config import load_settings

    overrides: dict[str, Any] = {
        "llm.backend": backend,
        "llm.base_url": base_url,
        "llm.cache": False if no_cache else None,
    }
    if model is not None:
        effective_backend = backend or load_settings(config).llm.backend
        is_gguf = effective_backend == "llamacpp" or model.endswith(".gguf")
        overrides["llm.model_path" if is_gguf else "llm.model"] = model
    overrides.update(more)
    return load_settings(config, overrides)


def schema_by_name(name: str):
    """An artefact class (``TaskProposal``) or a nested record (``Scenario``) of ``anomalygen.schema``."""
    from pydantic import BaseModel

    from anomalygen import schema as schema_module

    known = dict(schema_module.ARTEFACTS)
    for attr, value in vars(schema_module).items():
        if (
            isinstance(value, type)
            and issubclass(value, BaseModel)
            and value.__module__.startswith(f"{schema_module.__name__}.")
        ):
            known.setdefault(attr, value)
    for key in (name, *(k for k in known if k.lower() == name.lower())):
        if key in known and key not in ("Artefact", "Strict"):
            return known[key]
    raise UserError(f"unknown schema {name!r}; choose one of: {', '.join(sorted(schema_module.ARTEFACTS))}")


@app.command()
def ping(
    backend: BackendOpt = None,
    model: ModelOpt = None,
    base_url: BaseUrlOpt = None,
    config: ConfigOpt = None,
    as_json: JsonOpt = False,
):
    """Send one tiny request (uncached) and print backend, model and latency."""
    from anomalygen.llm import get_client

    settings = llm_settings(config, backend, model, base_url)
    client = get_client(settings.llm)
    start = time.perf_counter()
    reply = client.complete(
        [{"role": "user", "content": "Reply with the single word: pong"}],
        max_tokens=8,
        temperature=0.0,
        cache=False,
    )
    latency = time.perf_counter() - start
    payload = {
        "backend": client.backend_name,
        "model": client.model,
        "latency_s": round(latency, 3),
        "reply": str(reply).strip()[:80],
        "prompt_tokens": client.usage.prompt_tokens,
        "completion_tokens": client.usage.completion_tokens,
    }
    if as_json:
        print(json.dumps(payload, indent=2))
    else:
        print(
            f"backend={payload['backend']} model={payload['model']} latency={latency:.2f}s reply={payload['reply']!r}"
        )


@app.command()
def ask(
    prompt: Annotated[str, typer.Argument(help="The user message.")],
    schema: Annotated[
        str | None, typer.Option("--schema", help="Validate the reply as this artefact, e.g. TaskProposal.")
    ] = None,
    system: Annotated[str | None, typer.Option("--system", help="Optional system message.")] = None,
    backend: BackendOpt = None,
    model: ModelOpt = None,
    base_url: BaseUrlOpt = None,
    temperature: Annotated[float | None, typer.Option(help="Sampling temperature.")] = None,
    seed: Annotated[int | None, typer.Option(help="Sampling seed (where the backend supports one).")] = None,
    max_tokens: Annotated[int | None, typer.Option("--max-tokens", help="Reply token limit.")] = None,
    no_cache: NoCacheOpt = False,
    config: ConfigOpt = None,
    as_json: JsonOpt = False,
):
    """Ask one question; with --schema print the validated object as JSON."""
    from anomalygen.llm import get_client

    if not prompt.strip():
        raise UserError("the prompt is empty")
    model_cls = schema_by_name(schema) if schema else None
    settings = llm_settings(config, backend, model, base_url, no_cache)
    client = get_client(settings.llm)
    messages = ([{"role": "system", "content": system}] if system else []) + [
        {"role": "user", "content": prompt}
    ]
    start = time.perf_counter()
    result = client.complete(
        messages, schema=model_cls, temperature=temperature, seed=seed, max_tokens=max_tokens
    )
    wall = time.perf_counter() - start
    if model_cls is not None:
        print(result.model_dump_json(indent=2))
    elif as_json:
        print(json.dumps({"text": result}, ensure_ascii=False, indent=2))
    else:
        print(result)
    sys.stdout.flush()
    u = client.usage
    print(
        f"{client.backend_name}:{client.model} {wall:.2f}s requests={u.requests} tokens={u.prompt_tokens}+{u.completion_tokens}"
        f" cache={u.cache_hits}hit/{u.cache_misses}miss retries={u.retries}",
        file=sys.stderr,
    )
