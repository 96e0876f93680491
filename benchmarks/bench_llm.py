"""LLM-layer figures: local GGUF structured output speed, cache replay cost, client overhead.

Run: ``.venv/bin/python benchmarks/bench_llm.py [--seeds 3] [--json]``. Prints one JSON object.
- ``gguf``: the bundled SmolLM2-135M through the llamacpp backend producing a validated TaskProposal
  (the ``anomalygen llm ask --backend llamacpp --schema TaskProposal`` path), per seed: wall time,
  tokens, tokens/s, repair turns.
- ``cache``: the same requests replayed from the SQLite cache (no model call).
- ``http``: validated completions per second against the local scripted OpenAI-compatible server
  (measures our client + SDK overhead, not a model), at concurrency 1 and 4.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PROMPT = "A knife lies on the edge of a kitchen counter"


def bench_gguf(seeds: int, cache_dir: Path) -> dict:
    from anomalygen.config import LLMConfig
    from anomalygen.llm import LLMItemError, get_client
    from anomalygen.schema import TaskProposal

    cfg = LLMConfig(backend="llamacpp", cache_path=str(cache_dir / "gguf.sqlite"))
    runs = []
    load_start = time.perf_counter()
    client = get_client(cfg)
    client.backend.server.ensure_running()  # child process up, model loaded, server listening
    load_s = time.perf_counter() - load_start
    for seed in range(seeds):
        client.reset_usage()
        start = time.perf_counter()
        try:
            client.complete([{"role": "user", "content": PROMPT}], schema=TaskProposal, seed=seed)
            ok = True
        except LLMItemError:
            ok = False
        wall = time.perf_counter() - start
        u = client.usage
        runs.append(
            {
                "seed": seed,
                "valid": ok,
                "wall_s": round(wall, 2),
                "prompt_tokens": u.prompt_tokens,
                "completion_tokens": u.completion_tokens,
                "completion_tok_per_s": round(u.completion_tokens / wall, 1) if wall else None,
                "repair_turns": u.retries,
            }
        )
    replay = get_client(cfg)
    start = time.perf_counter()
    for seed in range(seeds):
        try:
            replay.complete([{"role": "user", "content": PROMPT}], schema=TaskProposal, seed=seed)
        except LLMItemError:
            pass
    cache_ms = (time.perf_counter() - start) / seeds * 1000
    return {
        "model": client.model,
        "load_s": round(load_s, 2),
        "runs": runs,
        "cache": {
            "replay_ms_per_request": round(cache_ms, 2),
            "hits": replay.usage.cache_hits,
            "requests": replay.usage.requests,
        },
    }


def bench_http(cache_dir: Path, n: int = 60) -> dict:
    sys.path.insert(0, str(ROOT / "tests"))
    from anomalygen.llm import get_client
    from anomalygen.schema import Scenario
    from support.fixtures import llm_config_for
    from support.openai_server import ScriptedOpenAIServer, text

    reply = text(json.dumps({"hazard_object": "knife", "room": "kitchen", "placement": "counter_edge"}))
    out = {}
    with ScriptedOpenAIServer([reply]) as srv:
        for conc in (1, 4):
            client = get_client(llm_config_for(srv, cache_dir, cache=False, concurrency=conc))
            batch = [[{"role": "user", "content": f"scene {i}"}] for i in range(n)]
            start = time.perf_counter()
            results = client.complete_many(batch, schema=Scenario)
            wall = time.perf_counter() - start
            assert all(isinstance(r, Scenario) for r in results)
            out[f"concurrency_{conc}"] = {"requests": n, "per_s": round(n / wall, 1)}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--skip-gguf", action="store_true")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench-llm-") as tmp:
        result = {"http": bench_http(Path(tmp))}
        if not args.skip_gguf:
            result["gguf"] = bench_gguf(args.seeds, Path(tmp))
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
