"""A `kill -9` of `anomalygen run` while learn executes leaves no worker or execution child behind.

Learn is the stage whose processes outlived their parent before (two workers still at 20-27 % CPU a
quarter of an hour later): each worker starts an isolated child per execution, so the tree is two deep.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

from support.processes import depth_below, descendants, wait_gone

LEARN_DEADLINE_S = 600  # brainstorm, build, detect and plan of two tasks on a loaded 2-core machine


def _config(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text('quiet = true\n[brainstorm]\nengine = "knowledge"\nn = 2\n'
                    "[learn]\nseeds = 2\nvideo = false\n[evaluate]\nbaselines = false\nimage_metrics = false\n")
    return path


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_killing_run_during_learn_leaves_no_worker_behind(tmp_path):
    run_dir = tmp_path / "run"
    env = {k: v for k, v in os.environ.items() if not k.startswith("ANOMALYGEN_")} | {"MUJOCO_GL": "egl"}
    cmd = [sys.executable, "-c", "from anomalygen.cli import main; main()", "run", "--out", str(run_dir),
           "--config", str(_config(tmp_path)), "--workers", "2"]
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + LEARN_DEADLINE_S
        below: set[int] = set()
        while time.monotonic() < deadline and proc.poll() is None:
            # learn has begun once a plan exists and a worker has started its isolated execution child
            below = descendants(proc.pid)
            if list(run_dir.glob("plans/*.json")) and any(depth_below(proc.pid, p) == 2 for p in below):
                break
            time.sleep(0.2)
        assert proc.poll() is None, "the run ended before learn could be caught executing"
        assert any(depth_below(proc.pid, p) == 2 for p in below), "learn never started an execution child"
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=10)
        assert wait_gone(below, 20.0) == set()
    finally:
        proc.kill()
        proc.wait(timeout=10)
