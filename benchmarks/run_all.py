"""``make bench``: run every ``benchmarks/bench_*.py``, collect their JSON into results.json, print a table.

Each benchmark is its own process (clean imports and timings) and prints one JSON object as its last
stdout line. A failing benchmark is recorded with its error and does not stop the others.
"""

import json
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main() -> int:
    results, failed = {}, 0
    for script in sorted(HERE.glob("bench_*.py")):
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, str(script)], capture_output=True, text=True)
        wall = round(time.perf_counter() - t0, 2)
        lines = [ln for ln in proc.stdout.splitlines() if ln.strip().startswith("{")]
        if proc.returncode == 0 and lines:
            results[script.stem] = {**json.loads(lines[-1]), "wall_s": wall}
        else:
            failed += 1
            results[script.stem] = {"error": (proc.stderr or proc.stdout).strip().splitlines()[-1:] or ["no output"], "wall_s": wall}
    (HERE / "results.json").write_text(json.dumps(results, indent=2) + "\n")
    from rich.console import Console
    from rich.table import Table

    table = Table(title="benchmarks (results.json)")
    table.add_column("benchmark")
    table.add_column("figures")
    for name, res in results.items():
        table.add_row(name, ", ".join(f"{k}={v}" for k, v in res.items() if k != "name"))
    Console().print(table)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
