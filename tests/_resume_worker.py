"""A slow stage run in a subprocess so a test can SIGKILL it mid-way and resume (see test_runfolder)."""

import sys
import time

from anomalygen.config import load_settings
from anomalygen.runfolder import RunFolder, try_read_model, write_model
from anomalygen.runner import run_items
from anomalygen.schema import Hypothesis

PAD = "x" * 200_000  # large files make a mid-write kill likely to hit a partially written temp file


def make_item(item_id, payload, ctx):
    time.sleep(payload)
    write_model(ctx.run.root / "items" / f"{item_id}.json",
                Hypothesis(rank=1, problem=item_id, solution=PAD, target_object=item_id))
    with open(ctx.run.root / "log.txt", "a") as fh:  # one line per execution, to count repeats
        fh.write(item_id + "\n")


if __name__ == "__main__":
    root, n, delay = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
    run = RunFolder.create(root)
    settings = load_settings(overrides={"workers": 1, "quiet": True})
    items = [(f"item{i:03d}", delay) for i in range(n)]
    summary = run_items(
        run, "demo", items, make_item, settings=settings,
        is_done=lambda i: try_read_model(run.root / "items" / f"{i}.json", Hypothesis) is not None,
    )
    print(summary.line())
