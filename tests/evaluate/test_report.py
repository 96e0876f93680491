"""The HTML report: sections present, copes with missing stages, renders in headless Chromium."""

import shutil
import subprocess
from html.parser import HTMLParser

import numpy as np
import pytest

from anomalygen.config import Settings
from anomalygen.evaluate import report
from anomalygen.evaluate.report import SECTIONS, run_stage
from anomalygen.runfolder import RunFolder

from .conftest import build_synthetic_run


def _settings():
    s = Settings(quiet=True)
    s.evaluate.baselines = False  # the baselines have their own tests; keep this one fast
    s.evaluate.wmd_pairs = 20
    return s


class _Sections(HTMLParser):
    def __init__(self):
        super().__init__()
        self.ids, self.imgs, self.videos = [], 0, []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "section":
            self.ids.append(a.get("id"))
        elif tag == "img" and (a.get("src") or "").startswith("data:image/png;base64,"):
            self.imgs += 1
        elif tag == "video":
            self.videos.append(a.get("src"))


def test_full_report(synthetic_run):
    summary = run_stage(synthetic_run, _settings())
    assert summary.done == 1
    index = synthetic_run.report_dir / "index.html"
    parser = _Sections()
    parser.feed(index.read_text())
    assert parser.ids == list(SECTIONS)
    assert parser.imgs >= 3 + 5  # pie, success bars, hit@k + five embedded renders
    assert len(parser.videos) == 5 and all((synthetic_run.report_dir / v).is_file() for v in parser.videos)
    data = report.Report.model_validate_json((synthetic_run.report_dir / "report.json").read_text())
    assert data.evaluation.success.verdicts.resolved == 2 and data.evaluation.success.robot_check.successes == 3
    md = (synthetic_run.report_dir / "summary.md").read_text()
    assert "recall 0.80 (4/5)" in md and "| **all** | 5 | 2/5 (40%) | - | 3/5 |" in md
    html = index.read_text()
    # the headline tiles are the truth's and the referee's; the robot's own check only beside them
    assert "<div><b>2/5</b>resolved (referee)</div>" in html and "<div><b>4/5</b>detection recall (truth)</div>" in html
    assert "<div><b>3/5</b>robot&#x27;s own check</div>" in html
    assert ">success<" not in html and "hit@1" not in html.split('id="detection"')[0]
    knife = next(g for g in data.gallery if g.task_id == "knife_at_edge")
    assert knife.verdicts == {"unresolved": 1} and knife.robot_check == 1 and (knife.found, knife.hazards) == (1, 1)


def test_report_with_only_tasks_says_not_run(tmp_path):
    run = build_synthetic_run(tmp_path / "partial", stages=("brainstorm",))
    run_stage(run, _settings())
    html = (run.report_dir / "index.html").read_text()
    for stage in ("detect", "learn"):
        assert f"the {stage} stage has produced no artefacts yet" in html
    assert "no render (not run)" in html
    data = report.Report.model_validate_json((run.report_dir / "report.json").read_text())
    assert set(data.evaluation.not_run) >= {"build", "detect", "learn"}


def test_report_on_empty_run(tmp_path):
    run = RunFolder.create(tmp_path / "empty")
    run_stage(run, _settings())
    html = (run.report_dir / "index.html").read_text()
    assert html.count("not run") >= 5


@pytest.mark.slow
def test_report_renders_in_headless_chromium(synthetic_run, tmp_path):
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        pytest.skip("chromium not installed (make test installs it with apt-get)")
    run_stage(synthetic_run, _settings())
    shot = tmp_path / "shot.png"
    index = (synthetic_run.report_dir / "index.html").resolve()
    subprocess.run(
        [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         f"--user-data-dir={tmp_path / 'profile'}", f"--screenshot={shot}", "--window-size=1280,2000",
         index.as_uri()],
        check=True, capture_output=True, timeout=120,
    )
    from PIL import Image

    img = np.asarray(Image.open(shot).convert("RGB"), dtype=np.float32)
    assert img.shape[:2] == (2000, 1280)
    assert img.std() > 20  # not blank: header, tables and plots
    header = img[:60].mean(axis=(0, 1))
    assert header[2] > header[0] + 20  # the dark blue header bar rendered with the inline CSS
