"""The one-command pipeline: it follows the one stage registry, a failing stage does not stop the
others, a killed run resumes without duplicates, and Ray produces the same artefacts as locally."""

import importlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import pytest

from anomalygen import pipeline
from anomalygen import stages as registry
from anomalygen.config import Settings, load_settings
from anomalygen.errors import UserError
from anomalygen.runfolder import RunFolder


@dataclass(frozen=True)
class _FailingStage:
    name: str = "ghost"
    inputs: tuple = ()
    outputs: tuple = ()

    def run(self, run, settings, *, force=False, only=None):
        raise UserError("ghost has nothing to work on")


def test_a_failing_stage_is_reported_and_later_stages_still_run(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(registry, "STAGES", (_FailingStage(), registry.stage("report")))
    settings = Settings(quiet=True)
    settings.evaluate.baselines = False
    result = pipeline.run_pipeline(RunFolder.create(tmp_path / "r"), settings)
    assert result["stages"]["ghost"] == {"status": "failed", "reason": "ghost has nothing to work on"}
    assert result["stages"]["report"]["status"] == "done"
    assert result["report"].endswith("index.html") and Path(result["report"]).is_file()
    assert "report: " in capsys.readouterr().out


def test_one_registry_names_every_stage_the_cli_and_the_pipeline_run():
    from anomalygen.cli import app

    names = [s.name for s in registry.STAGES]
    assert names == ["brainstorm", "build", "detect", "plan", "learn", "judge", "evaluate", "report"]
    commands = {c.name or c.callback.__name__ for c in app.registered_commands}
    assert set(names) <= commands
    for s in registry.STAGES:  # every module exists and has the entry point the registry calls
        assert callable(importlib.import_module(s.module).run_stage)
        assert s.outputs, s.name
    # stage modules live in the package of the same name (build's package is scene/, report's evaluate/)
    assert registry.stage("plan").module == "anomalygen.plan.stage"
    assert registry.stage("learn").module == "anomalygen.learn.stage"
    assert registry.stage("judge").module == "anomalygen.referee.stage"  # the referee judges after the robot


def test_a_whole_run_stage_refuses_only(tmp_path):
    with pytest.raises(ValueError, match="takes no --only"):
        registry.stage("evaluate").run(RunFolder.create(tmp_path / "r"), Settings(quiet=True), only=["t"])


def test_demo_defaults_are_the_embedded_offline_ones():
    s = load_settings(pipeline.demo_config_path())
    assert (s.brainstorm.engine, s.build.engine, s.plan.engine) == ("knowledge",) * 3
    assert s.detect.detector == "rules" and s.llm.backend == "none"
    assert 15 <= s.brainstorm.n <= 25 and s.learn.sac_steps <= 1000


def _config(tmp_path, n):
    # videos off: rendering them was 110 of learn's 130 s on five tasks, and these tests check resume and
    # executors, not videos (test_learn_stage and the demo cover those)
    path = tmp_path / "small.toml"
    path.write_text(
        f"workers = 1\nquiet = true\n[brainstorm]\nengine = \"knowledge\"\nn = {n}\n"
        "[learn]\nsac_steps = 50\nvideo = false\n[evaluate]\nbaselines = false\nwmd_pairs = 10\nimage_metrics = false\n"
    )
    return path


def _cli(*args, env=None):
    return [sys.executable, "-c", "from anomalygen.cli import main; main()", *args]


def _env(**extra):
    env = {**os.environ, "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1", "RAY_AUTH_MODE": "disabled", **extra}
    return {k: v for k, v in env.items() if not k.startswith("ANOMALYGEN_") or k in extra}


@pytest.mark.slow
def test_killed_run_resumes_without_duplicates_or_losses(tmp_path):
    pytest.importorskip("anomalygen.scene.stage")
    run_dir, cfg = tmp_path / "run", _config(tmp_path, 5)
    proc = subprocess.Popen(_cli("run", "--out", str(run_dir), "--config", str(cfg)), env=_env(),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 240
    killed = False
    while time.time() < deadline and proc.poll() is None:
        built = list((run_dir / "scenes").glob("*/scene.json"))
        if built:  # a stage is half-way: some items done, the rest not
            proc.send_signal(signal.SIGKILL)
            killed = True
            break
        time.sleep(0.2)
    proc.wait(timeout=30)
    assert killed, "the run finished before it could be killed; make the run bigger"

    done = subprocess.run(_cli("run", "--out", str(run_dir), "--config", str(cfg), "--json"), env=_env(),
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    result = json.loads(done.stdout)  # --json: nothing else on stdout
    ids = [json.loads(line)["id"] for line in (run_dir / "tasks.jsonl").read_text().splitlines() if line.strip()]
    assert len(ids) == len(set(ids)) == 5
    scenes = sorted(p.parent.name for p in (run_dir / "scenes").glob("*/scene.json"))
    failed = {e.name.removesuffix(".json") for e in (run_dir / "errors" / "build").glob("*.json")} if (run_dir / "errors" / "build").is_dir() else set()
    assert sorted(set(scenes) | failed) == sorted(ids)  # nothing lost
    assert result["stages"]["build"]["skipped"] >= 1  # resumed, not redone
    assert not list(run_dir.rglob("*.tmp*"))  # no half-written files left behind
    assert (run_dir / "report" / "index.html").is_file()


def _scene_files(run_dir: Path) -> dict[str, str]:
    return {str(p.relative_to(run_dir)): p.read_text() for p in sorted(run_dir.glob("scenes/*/scene.json"))}


@pytest.mark.slow
@pytest.mark.ray
def test_ray_executor_gives_identical_artefacts(tmp_path):
    pytest.importorskip("ray")
    pytest.importorskip("anomalygen.scene.stage")
    cfg = _config(tmp_path, 3)
    ray_tmp = tempfile.mkdtemp(prefix="ray", dir="/tmp")
    outs = {}
    for name, extra in (("local", ["--workers", "2"]), ("ray", ["--executor", "ray", "--workers", "2"])):
        run_dir = tmp_path / name
        for stage in ("brainstorm", "build"):
            args = [stage, "--run", str(run_dir), "--config", str(cfg), "--quiet"]
            if stage == "build":
                args += extra
            r = subprocess.run(_cli(*args), env=_env(ANOMALYGEN_RAY_TMP=ray_tmp), capture_output=True, text=True, timeout=300)
            assert r.returncode == 0, r.stderr[-2000:]
        outs[name] = run_dir
    assert (outs["local"] / "tasks.jsonl").read_text() == (outs["ray"] / "tasks.jsonl").read_text()
    local, ray = _scene_files(outs["local"]), _scene_files(outs["ray"])
    assert len(local) == 3 and local.keys() == ray.keys()
    assert local == ray
