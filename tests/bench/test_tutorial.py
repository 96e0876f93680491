"""docs/agents.md's tutorial runs as written: its agent module, its bench command and its env snippet,
on a tiny suite."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

from anomalygen.runfolder import RunFolder, read_model
from anomalygen.schema import BenchReport, EpisodeRecord

DOC = Path(__file__).parents[2] / "docs" / "agents.md"


def _blocks(lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)


def test_the_tutorial_runs_as_written(tiny_suite, tmp_path, capsys):
    module = next(b for b in _blocks("python") if b.startswith("# my_agent.py"))
    (tmp_path / "my_agent.py").write_text(module)
    bench = next(line for b in _blocks("bash") for line in b.splitlines() if line.startswith("anomalygen bench"))
    args = shlex.split(bench)[1:]
    args[args.index("--suite") + 1] = str(tiny_suite.root)
    out = tmp_path / "bench"
    first = tiny_suite.task_ids[0]
    exe = Path(sys.executable).with_name("anomalygen")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), *sys.path])}
    done = subprocess.run([str(exe), *args, "--out", str(out), "--only", first, "--quiet"], env=env,
                          capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-2000:]
    report = read_model(out / "bench.json", BenchReport)
    assert report.agent == "my_agent:SwitchOffWhatIsOn" and report.runs == 1
    ep = read_model(RunFolder(out).skill_dir(first, 0) / "episode.json", EpisodeRecord)
    assert ep.calls[-1].call == "done" and "runs resolved" in done.stderr

    snippet = next(b for b in _blocks("python") if "make_env(SCENE" in b)
    exec(compile(snippet, str(DOC), "exec"), {"SCENE": RunFolder(tiny_suite.root).scene_dir(first)})
    printed = capsys.readouterr().out.splitlines()
    assert printed[0].startswith("Room: ") and "pick_place(object, destination" in printed[0]
    assert "'nothing_0' is not an object in the scene" in printed[1]
    assert printed[2] in ("no_action_needed False", "acted_on_safe False", "unresolved False")
