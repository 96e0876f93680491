"""Asset library benchmarks; prints one JSON object.

- generate + compile one asset: median over every vocabulary name x a few seeds (target <= 50 ms);
- embed and search a catalogue of >= 1,000 assets from a cold cache (target <= 30 s on 2 cores).

Usage: ``python benchmarks/bench_assets.py [--seeds 3] [--variants 9]``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import tempfile
import time


def bench_generate(seeds: int) -> dict:
    from anomalygen.assets import generate, household_names, target_names

    names = target_names() + household_names()
    generate("pill", 0).spec.compile()  # warm imports
    times, per_target = [], []
    for name in names:
        for seed in range(seeds):
            t = time.perf_counter()
            generate(name, seed).spec.compile()
            dt = (time.perf_counter() - t) * 1000
            times.append(dt)
            if name in target_names():
                per_target.append(dt)
    return {
        "assets": len(times),
        "median_ms": round(statistics.median(times), 3),
        "p90_ms": round(sorted(times)[int(0.9 * len(times))], 3),
        "max_ms": round(max(times), 3),
        "targets_median_ms": round(statistics.median(per_target), 3),
        "target_ms": 50.0,
        "pass": statistics.median(times) <= 50.0,
    }


def bench_search(variants: int) -> dict:
    os.environ["ANOMALYGEN_CACHE_DIR"] = tempfile.mkdtemp(prefix="ag-bench-")  # cold cache
    from anomalygen.assets import retrieval
    from anomalygen.embedding import encoder

    t0 = time.perf_counter()
    encoder()
    load_s = time.perf_counter() - t0
    t1 = time.perf_counter()
    entries = retrieval.catalogue(variants)
    build_s = time.perf_counter() - t1
    t2, c2 = time.perf_counter(), time.process_time()
    retrieval.embeddings(entries)
    embed_s, embed_cpu = time.perf_counter() - t2, time.process_time() - c2
    tok = encoder().tokenizer
    tokens_split = sum(len(tok(e.variant_text)["input_ids"]) for e in entries) + sum(
        len(tok(b)["input_ids"]) for b in {e.base_text for e in entries}
    )
    tokens_full = sum(len(tok(e.description)["input_ids"]) for e in entries)
    t3 = time.perf_counter()
    queries = [
        "something a toddler could choke on",
        "sharp kitchen tool",
        "open fridge door",
        "medicine bottle",
        "hot appliance",
    ]
    for q in queries:
        retrieval.search(q, entries, 5)
    search_s = (time.perf_counter() - t3) / len(queries)
    retrieval._MEM.clear()
    t4 = time.perf_counter()
    retrieval.embeddings(entries)
    disk_s = time.perf_counter() - t4
    total = build_s + embed_s + search_s
    # Wall time on a shared machine mostly measures the other tenants; CPU time over 2 threads is what
    # a quiet 2-core machine would take.
    quiet_estimate = build_s + embed_cpu / 2 + search_s
    return {
        "catalogue_size": len(entries),
        "model_load_s": round(load_s, 2),
        "catalogue_build_s": round(build_s, 2),
        "embed_s": round(embed_s, 2),
        "embed_cpu_s": round(embed_cpu, 2),
        "embed_cpu_s_per_core_of_2": round(embed_cpu / 2, 2),
        "tokens_embedded": tokens_split,
        "tokens_if_full_descriptions": tokens_full,
        "search_s_per_query": round(search_s, 4),
        "reload_from_disk_cache_s": round(disk_s, 4),
        "embed_and_search_s": round(total, 2),
        "embed_and_search_quiet_estimate_s": round(quiet_estimate, 2),
        "target_s": 30.0,
        "pass": total <= 30.0,
        "pass_quiet_estimate": quiet_estimate <= 30.0,
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--variants", type=int, default=9, help="variants per name: 9 x 114 names = 1,026 assets")
    args = ap.parse_args()
    import torch

    torch.set_num_threads(min(2, os.cpu_count() or 1))
    result = {
        "benchmark": "assets",
        "machine": {
            "cpus": os.cpu_count(),
            "python": platform.python_version(),
            "load_avg": [round(x, 2) for x in os.getloadavg()],
        },
        "generate_compile": bench_generate(args.seeds),
        "embed_search": bench_search(args.variants),
    }
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
