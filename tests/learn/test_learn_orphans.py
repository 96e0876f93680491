"""A ``kill -9`` of ``anomalygen learn`` leaves no worker behind (issue 23: two kept running for 15 min)."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time

import pytest
from test_learn_stage import _task, scene  # noqa: F401  (the module-scoped built scene)

from support.processes import depth_below, descendants, wait_gone


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_killing_learn_leaves_no_worker_behind(tmp_path, scene):  # noqa: F811 (the imported fixture)
    from anomalygen.config import Settings
    from anomalygen.detect.stage import run_stage as detect
    from anomalygen.plan.stage import run_stage as plan
    from anomalygen.runfolder import RunFolder, write_jsonl

    run = RunFolder.create(tmp_path / "r")
    write_jsonl(run.tasks_path, [_task("a")])
    shutil.copytree(scene[0], run.scene_dir("a"))
    settings = Settings(quiet=True, workers=1)
    assert detect(run, settings).done == 1 and plan(run, settings).done == 1  # a real pick-and-place plan
    env = {k: v for k, v in os.environ.items() if not k.startswith("ANOMALYGEN_")}
    cmd = [sys.executable, "-c", "from anomalygen.cli import main; main()", "learn", "--run", str(run.root),
           "--workers", "2", "--seeds", "2", "--quiet"]
    proc = subprocess.Popen(cmd, env={**env, "ANOMALYGEN_LEARN__VIDEO": "false"},
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        # wait until a pool worker has started its per-execution process (two generations down)
        deadline = time.monotonic() + 300
        below: set[int] = set()
        while time.monotonic() < deadline and proc.poll() is None:
            below = descendants(proc.pid)
            if any(depth_below(proc.pid, p) == 2 for p in below):
                break
            time.sleep(0.2)
        assert proc.poll() is None and any(depth_below(proc.pid, p) == 2 for p in below), "no execution started"
        below |= descendants(proc.pid)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=10)
        assert wait_gone(below, 20.0) == set()
    finally:
        proc.kill()
