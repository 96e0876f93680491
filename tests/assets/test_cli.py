"""``anomalygen assets ...`` through typer's runner."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from anomalygen.assets.cli import app

runner = CliRunner()


def test_list_and_show_json():
    res = runner.invoke(app, ["list", "--json"])
    assert res.exit_code == 0
    rows = json.loads(res.stdout)
    assert len(rows) == 126 and sum(r["kind"] == "target" for r in rows) == 44
    # every name says where its models come from, each with its licence
    assert all(r["sources"] and r["licences"] == sorted({s["licence"] for s in r["sources"]}) for r in rows)
    by_name = {r["name"]: r for r in rows}
    assert [s["source"] for s in by_name["Microwave"]["sources"]] == ["procedural", "gymnasium-robotics"]
    assert [s["source"] for s in by_name["Stove"]["sources"]] == ["procedural", "gymnasium-robotics"] and by_name["pill"]["real_models"] == 0
    assert sum(r["real_models"] > 0 for r in rows if r["kind"] == "target") >= 12
    res = runner.invoke(app, ["show", "Dishwasher", "--seed", "1", "--json"])
    info = json.loads(res.stdout)
    assert {j["label"] for j in info["joints"]} >= {"door", "rack"}
    assert info["aabb"][0][2] == 0.0


def test_render_writes_a_png(tmp_path):
    out = tmp_path / "x.png"
    res = runner.invoke(
        app, ["render", "Laptop", "--seed", "2", "--out", str(out), "--width", "120", "--height", "90"]
    )
    assert res.exit_code == 0, res.output
    from PIL import Image

    im = Image.open(out)
    assert im.size == (120, 90)


def test_validate_reports_categories_and_exit_code():
    res = runner.invoke(
        app, ["validate", "-n", "1", "--name", "Toaster", "--name", "pill", "--no-render", "--json"]
    )
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout)
    assert summary["passed"] == 2 and summary["assets_ok"] == 2


def test_show_real_gives_the_packaged_model_with_its_licence():
    res = runner.invoke(app, ["show", "Stove", "--real", "--json"])
    assert res.exit_code == 0, res.output
    info = json.loads(res.stdout)
    assert (info["source"], info["package"], info["licence"]) == ("packaged", "gymnasium-robotics", "Apache-2.0")
    assert [j["label"] for j in info["joints"]] == ["knob"] * 4 and all(j["closed"] == 0.0 for j in info["joints"])
    res = runner.invoke(app, ["show", "Dishwasher", "--real", "--json"])  # no real model: procedural
    assert json.loads(res.stdout)["source"] == "procedural"


def test_validate_real_checks_each_packaged_model():
    res = runner.invoke(app, ["validate", "--real", "--name", "StorageFurniture", "--no-render", "--json"])
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout)
    assert summary["names"] == 1 and summary["assets"] == 2 and summary["assets_ok"] == 2


def test_search_json(tmp_path, monkeypatch):
    monkeypatch.setenv("ANOMALYGEN_CACHE_DIR", str(tmp_path))
    res = runner.invoke(
        app, ["search", "cold food storage appliance", "-k", "3", "--variants", "1", "--json"]
    )
    assert res.exit_code == 0, res.output
    hits = json.loads(res.stdout)
    assert len(hits) == 3 and "Refrigerator" in [h["name"] for h in hits]


def test_gallery_function_labels_every_cell():
    from anomalygen.assets.render import gallery

    sheet = gallery(["pill", "Kettle", "Chair"], cell=64, cols=3)
    assert sheet.shape == (64 + 18, 192, 3)
    assert sheet[:64].std() > 5  # thumbnails are not blank


def test_unknown_name_is_a_user_error():
    res = runner.invoke(app, ["show", "Spaceship"])
    assert res.exit_code != 0
