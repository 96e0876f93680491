"""``--json`` prints only JSON on stdout, even when a library prints there (EfficientNet's loader does)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from .conftest import build_synthetic_run


@pytest.mark.slow
def test_evaluate_json_is_the_only_thing_on_stdout(tmp_path):
    run = build_synthetic_run(tmp_path / "synth")
    env = {k: v for k, v in os.environ.items() if not k.startswith("ANOMALYGEN_")}
    env["ANOMALYGEN_EVALUATE__BASELINES"] = "false"  # image metrics stay on: they load EfficientNet
    done = subprocess.run([sys.executable, "-c", "from anomalygen.cli import main; main()", "evaluate",
                           "--run", str(run.root), "--json"], env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    out = json.loads(done.stdout)
    assert out["stage"] == "evaluate" and out["done"] == 1
    # what the libraries and the tables said went to stderr
    assert "Loaded pretrained weights for efficientnet-lite0" in done.stderr
    assert "detection against the truth" in done.stderr and "referee's verdict" in done.stderr
