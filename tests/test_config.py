"""Configuration precedence (TOML < env < flags), validation errors and secret masking."""

import pytest

from anomalygen.config import load_settings
from anomalygen.errors import UserError
from anomalygen.schema import Engine


@pytest.fixture
def toml_file(tmp_path):
    path = tmp_path / "cfg.toml"
    path.write_text('seed = 5\nworkers = 3\n[llm]\nmodel = "from-toml"\ntemperature = 0.1\n[detect]\nk = 2\n')
    return path


def test_defaults_use_the_offline_engine_when_no_llm_is_configured():
    s = load_settings()
    assert s.llm.backend == "none"
    assert s.engine_for("brainstorm") is Engine.KNOWLEDGE
    assert s.engine_for("plan") is Engine.KNOWLEDGE


def test_llm_engine_is_the_default_once_an_llm_is_configured():
    s = load_settings(overrides={"llm.backend": "openai"})
    assert s.engine_for("brainstorm") is Engine.LLM
    s = load_settings(overrides={"llm.backend": "openai", "brainstorm.engine": "knowledge"})
    assert s.engine_for("brainstorm") is Engine.KNOWLEDGE


def test_toml_then_env_then_flags_in_increasing_precedence(toml_file, monkeypatch):
    s = load_settings(toml_file)
    assert (s.seed, s.workers, s.llm.model, s.detect.k) == (5, 3, "from-toml", 2)

    monkeypatch.setenv("ANOMALYGEN_SEED", "7")
    monkeypatch.setenv("ANOMALYGEN_LLM__MODEL", "from-env")
    s = load_settings(toml_file)
    assert (s.seed, s.workers, s.llm.model) == (7, 3, "from-env")
    assert s.llm.temperature == 0.1  # a sibling from TOML survives an env override in the same section

    s = load_settings(toml_file, {"seed": 9, "llm.model": "from-flag", "workers": None})
    assert (s.seed, s.workers, s.llm.model, s.llm.temperature) == (9, 3, "from-flag", 0.1)


def test_invalid_values_fail_with_the_field_named(tmp_path, monkeypatch):
    from pydantic import ValidationError

    monkeypatch.setenv("ANOMALYGEN_DETECT__K", "lots")
    with pytest.raises(ValidationError, match="k"):
        load_settings()


def test_missing_or_broken_config_files_are_user_errors(tmp_path):
    with pytest.raises(UserError, match="not found"):
        load_settings(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("seed = = 3")
    with pytest.raises(UserError, match="invalid TOML"):
        load_settings(bad)


def test_unknown_config_keys_are_rejected(tmp_path):
    from pydantic import ValidationError

    path = tmp_path / "typo.toml"
    path.write_text("[detect]\nkk = 3\n")
    with pytest.raises(ValidationError, match="kk"):
        load_settings(path)


def test_secrets_are_masked_in_dumps(monkeypatch):
    monkeypatch.setenv("ANOMALYGEN_LLM__API_KEY", "sk-very-secret")
    s = load_settings()
    assert s.llm.api_key.get_secret_value() == "sk-very-secret"
    dumped = s.masked_dump()
    assert dumped["llm"]["api_key"] == "***"
    assert "sk-very-secret" not in str(dumped)


def test_the_plan_stage_reads_its_own_section(tmp_path, monkeypatch):
    path = tmp_path / "plan.toml"
    path.write_text('[plan]\nsource = "ground_truth"\nmax_fixes = 2\nsac_actions = ["close_joint"]\n[learn]\nseeds = 3\n')
    s = load_settings(path)
    assert (s.plan.source, s.plan.max_fixes, s.plan.sac_actions, s.learn.seeds) == ("ground_truth", 2, ["close_joint"], 3)
    monkeypatch.setenv("ANOMALYGEN_PLAN__SOURCE", "detected")
    assert load_settings(path).plan.source == "detected"
    assert load_settings(path, {"plan.source": "ground_truth"}).plan.source == "ground_truth"


def test_old_learn_keys_of_the_plan_stage_are_read_under_their_new_names_with_a_warning(tmp_path, monkeypatch, caplog):
    old = tmp_path / "old.toml"
    old.write_text('[learn]\nplan_source = "ground_truth"\nengine = "knowledge"\nmax_fixes = 2\nseeds = 3\n')
    with caplog.at_level("WARNING", logger="anomalygen.config"):
        s = load_settings(old)
    assert (s.plan.source, s.plan.engine, s.plan.max_fixes, s.learn.seeds) == ("ground_truth", Engine.KNOWLEDGE, 2, 3)
    said = caplog.text
    assert f"learn.plan_source (in {old}) is read as plan.source" in said and "learn.max_fixes" in said
    # precedence still holds across layers, whichever name each layer uses
    monkeypatch.setenv("ANOMALYGEN_LEARN__PLAN_SOURCE", "detected")
    caplog.clear()
    with caplog.at_level("WARNING", logger="anomalygen.config"):
        assert load_settings(old).plan.source == "detected"
    assert "ANOMALYGEN_LEARN__PLAN_SOURCE (in the environment) is read as ANOMALYGEN_PLAN__SOURCE" in caplog.text
    assert load_settings(old, {"plan.source": "ground_truth"}).plan.source == "ground_truth"


def test_old_and_new_name_disagreeing_in_one_layer_is_refused(tmp_path):
    both = tmp_path / "both.toml"
    both.write_text('[learn]\nplan_source = "ground_truth"\n[plan]\nsource = "detected"\n')
    with pytest.raises(UserError, match="learn.plan_source .* is the old name of plan.source"):
        load_settings(both)
    both.write_text('[learn]\nplan_source = "detected"\n[plan]\nsource = "detected"\n')
    assert load_settings(both).plan.source == "detected"
