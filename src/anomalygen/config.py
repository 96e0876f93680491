"""Effective configuration: TOML file < ``ANOMALYGEN_*`` environment < CLI flags.

One settings model for the whole pipeline, so a run's manifest can record exactly what produced it.
Nested sections map to env vars with a double underscore: ``ANOMALYGEN_LLM__BACKEND=openai``. Each
stage reads its own section; a key that moved to another section is still read under its old name,
with a warning that names the new one (``MOVED``).
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, SecretStr
from pydantic_settings import (
    BaseSettings,
    PydanticBaseSettingsSource,
    SettingsConfigDict,
    TomlConfigSettingsSource,
)

from anomalygen.schema import BrainstormMode, Engine

log = logging.getLogger(__name__)


class Section(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_assignment=True)


class LLMConfig(Section):
    backend: Literal["none", "openai", "anthropic", "llamacpp"] = "none"
    model: str | None = Field(None, description="model name for HTTP backends")
    base_url: str | None = Field(None, description="OpenAI-compatible endpoint, e.g. http://localhost:8000/v1")
    api_key: SecretStr | None = None
    model_path: str | None = Field(None, description="GGUF file for llamacpp; default: the bundled SmolLM2")
    temperature: float = Field(0.7, ge=0.0, le=2.0)
    max_tokens: int = Field(1024, ge=1)
    repair_retries: int = Field(3, ge=0, description="times an invalid reply goes back to the model")
    http_retries: int = Field(4, ge=0, description="retries on 429/5xx/timeouts, exponential backoff")
    timeout_s: float = Field(60.0, gt=0)
    concurrency: int = Field(4, ge=1)
    cache: bool = True
    cache_path: str | None = Field(None, description="SQLite cache file; default ~/.cache/anomalygen/llm.sqlite")
    price_prompt_per_mtok: float | None = Field(None, ge=0, description="USD per million prompt tokens")
    price_completion_per_mtok: float | None = Field(None, ge=0)
    vision: bool = Field(False, description="the endpoint accepts images (scene verification)")
    n_ctx: int = Field(4096, ge=256, description="llamacpp context size")
    threads: int | None = Field(
        None, ge=1, description="llamacpp CPU threads; default: the cores this process may use, less one, 1 to 4"
    )

    @property
    def configured(self) -> bool:
        return self.backend != "none"


class BrainstormConfig(Section):
    engine: Engine | None = Field(None, description="knowledge or llm; default knowledge unless an LLM is set")
    mode: BrainstormMode = BrainstormMode.BRAINSTORM
    n: int = Field(111, ge=1, description="number of proposals to keep")
    agents: int = Field(10, ge=1)
    rounds: int = Field(3, ge=1)
    novelty_threshold: float = Field(0.85, gt=0, le=1, description="SBERT cosine above which a proposal is a duplicate")
    tasks_file: str | None = Field(None, description="bring your own tasks.jsonl instead of brainstorming")
    tasks_text: str | None = Field(None, description="plain descriptions, one per line, grounded into tasks")


class BuildConfig(Section):
    engine: Engine | None = None
    clutter: int = Field(2, ge=0, description="unrelated everyday objects added per scene")
    near_misses: int = Field(1, ge=0, description="hazard-looking objects placed safely per scene (scene/mix.py)")
    multi_hazard: float = Field(0.25, ge=0, le=1, description="share of scenes given a second hazard (litter on the floor)")
    hazard_free: float = Field(
        0.15, ge=0, le=1, description="share of scenes built with the task's hazard made safe (shut away, closed)"
    )
    settle_s: float = Field(1.0, gt=0)
    render_width: int = Field(320, ge=32)
    render_height: int = Field(240, ge=32)
    repair_attempts: int = Field(3, ge=0)
    relevant_in_unit_cube: bool = Field(True, description="task assets inside (0..1)^3, unrelated ones outside")
    real_assets: bool = Field(
        True, description="draw real models from installed packages where a category has them (assets/real); "
        "false: procedural assets only, for comparisons"
    )
    start: Literal["dock", "reach"] = Field(
        "dock", description="where the robot starts: 'dock', the same pose in every scene (says nothing about the "
        "hazard); 'reach', the free pose nearest the dock with the hazard within reach, facing it (the answer "
        "key as a start pose: for tests and ablations of the skills alone)"
    )


class NoiseConfig(Section):
    """Perception noise on the scene graph the detectors read, so they are measured off the perfect
    graph too (``detect/noise.py``). Off by default; plan and learn always see the simulator."""

    enabled: bool = False
    pose_jitter: float = Field(0.02, ge=0, le=0.5, description="m: each object's position error bound, per axis (uniform)")
    miss_rate: float = Field(0.1, ge=0, le=1, description="chance that a small object is not seen at all")
    small_size: float = Field(0.06, gt=0, description="m: an object whose largest extent is at most this counts as small")
    confusion_rate: float = Field(
        0.1, ge=0, le=1, description="chance that an object with look-alikes (knowledge base) is seen as one of them"
    )


class DetectConfig(Section):
    detector: Literal["rules", "llm", "hybrid"] = "rules"
    k: int = Field(3, ge=1, le=10)
    noise: NoiseConfig = Field(default_factory=NoiseConfig)


class PlanConfig(Section):
    engine: Engine | None = Field(
        None, description="knowledge: the class's recipe; llm: the configured LLM decomposes the fix; "
        "default knowledge unless an LLM is set"
    )
    source: Literal["ground_truth", "detected"] = Field(
        "detected", description="detected: plan from the detections and the perceived scene alone; "
        "ground_truth: the oracle ablation (the builder's class and bindings)"
    )
    max_fixes: int = Field(
        3, ge=1, description="detected hazards fixed per scene, most severe first (and per look-again in learn)"
    )
    min_score: float = Field(0.0, description="hypotheses scoring below this are not acted on")
    sac_actions: list[str] = Field(
        default_factory=list,
        description="recipe actions the knowledge planner hands to SAC instead of a primitive, e.g. close_joint",
    )


class LearnConfig(Section):
    seeds: int = Field(1, ge=1)
    sac_steps: int = Field(2000, ge=0, description="SAC environment steps per SAC sub-task (paper: 1M)")
    retries: int = Field(
        1, ge=0, description="times a primitive sub-task whose success check fails right after it is run again"
    )
    recheck: bool = Field(
        True, description="after the plan, look at the scene again and fix hazards the robot's own actions "
        "created (a knob nudged on, a drawer left open); one pass, from perception (learn/recheck.py)"
    )
    video: bool = True
    n_envs: int = Field(
        1, ge=1, description="environments a SAC sub-task collects experience from at once (SB3 DummyVecEnv); "
        "more than 1 helps only with idle cores"
    )
    reward_mode: Literal["spec", "code"] = Field(
        "spec", description="code: SAC sub-tasks learn from reward code run in the sandbox (skills/learned/sandbox.py), "
        "the plan's own or its reward terms rendered as code; spec: the terms evaluated in-process"
    )


class EvaluateConfig(Section):
    image_metrics: bool = True
    vit_weights: str | None = Field(None, description="optional path to ViT/CLIP weights for image similarity")
    wmd_pairs: int = Field(300, ge=1, description="pairs sampled per text set for mean Word Mover's Distance")
    baselines: bool = Field(True, description="recompute the six benchmark baselines in the diversity table")
    # 50 texts per draw (issue 39): MetaWorld's whole list; RoboGen's public 46 and ManiSkill2's 20 fall short.
    draw_size: int = Field(50, ge=2, description="texts per draw for Self-BLEU and SBERT (a smaller set is measured "
                           "whole and flagged)")
    # 100 draws: the standard error of the mean is a tenth of the spread the table shows.
    draws: int = Field(100, ge=1, description="draws per text set; the table shows their mean and spread")
    text_judge_llm: bool = Field(
        False, description="text judge diagnostic: when an LLM is configured, ask it about hypotheses exact+SBERT "
        "judged a miss (detection itself is scored against the truth, not by this judge)")
    text_judge_threshold: float | None = Field(
        None, ge=-1, le=1, description="text judge diagnostic's SBERT threshold; default: the calibrated one")


class Settings(BaseSettings):
    """Everything a run needs. CLI flags arrive as init kwargs and win over env and TOML."""

    model_config = SettingsConfigDict(
        env_prefix="ANOMALYGEN_",
        env_nested_delimiter="__",
        extra="forbid",
        validate_assignment=True,
    )

    seed: int = 0
    executor: Literal["local", "ray"] = "local"
    workers: int = Field(2, ge=1)
    ray_address: str | None = None
    quiet: bool = False
    llm: LLMConfig = Field(default_factory=LLMConfig)
    brainstorm: BrainstormConfig = Field(default_factory=BrainstormConfig)
    build: BuildConfig = Field(default_factory=BuildConfig)
    detect: DetectConfig = Field(default_factory=DetectConfig)
    plan: PlanConfig = Field(default_factory=PlanConfig)
    learn: LearnConfig = Field(default_factory=LearnConfig)
    evaluate: EvaluateConfig = Field(default_factory=EvaluateConfig)

    @classmethod
    def settings_customise_sources(
        cls,
        settings_cls: type[BaseSettings],
        init_settings: PydanticBaseSettingsSource,
        env_settings: PydanticBaseSettingsSource,
        dotenv_settings: PydanticBaseSettingsSource,
        file_secret_settings: PydanticBaseSettingsSource,
    ) -> tuple[PydanticBaseSettingsSource, ...]:
        sources: list[PydanticBaseSettingsSource] = [init_settings, env_settings]
        toml_path = _CURRENT_TOML.get("path")
        if toml_path is not None:
            sources.append(_ConfigFileSource(settings_cls, toml_file=toml_path))
        # each layer's old key names are read as the new ones before the layers merge, so precedence holds
        return tuple(_MovedKeys(settings_cls, s, _layer_name(s, toml_path)) for s in sources)

    def engine_for(self, stage: Literal["brainstorm", "build", "plan"]) -> Engine:
        """The explicit per-stage engine, else ``llm`` exactly when an LLM is configured."""
        chosen = getattr(self, stage).engine
        if chosen is not None:
            return chosen
        return Engine.LLM if self.llm.configured else Engine.KNOWLEDGE

    def masked_dump(self) -> dict[str, Any]:
        """JSON-safe dump with every secret replaced, for manifests, logs and ``config show``."""
        data = self.model_dump(mode="json")
        if self.llm.api_key is not None:
            data["llm"]["api_key"] = "***"
        return data


# Keys that moved to another section: (old section, old key) -> (new section, new key). The plan stage
# used to read its settings from [learn].
MOVED: dict[tuple[str, str], tuple[str, str]] = {
    ("learn", "plan_source"): ("plan", "source"),
    ("learn", "engine"): ("plan", "engine"),
    ("learn", "max_fixes"): ("plan", "max_fixes"),
    ("learn", "min_score"): ("plan", "min_score"),
    ("learn", "sac_actions"): ("plan", "sac_actions"),
}


def _layer_name(source: PydanticBaseSettingsSource, toml_path: Path | None) -> str:
    from pydantic_settings import EnvSettingsSource

    if isinstance(source, TomlConfigSettingsSource):
        return str(toml_path)
    return "the environment" if isinstance(source, EnvSettingsSource) else "the arguments"


def _key(section: str, key: str, layer: str) -> str:
    return f"ANOMALYGEN_{section.upper()}__{key.upper()}" if layer == "the environment" else f"{section}.{key}"


def move_keys(data: dict[str, Any], layer: str) -> dict[str, Any]:
    """One layer's settings with every moved key under its new name, each with a warning; the old and
    the new name both given with different values in one layer is an error (neither is guessed)."""
    out = dict(data)
    for (old_sec, old_key), (new_sec, new_key) in MOVED.items():
        section = out.get(old_sec)
        if not isinstance(section, dict) or old_key not in section:
            continue
        section = dict(section)
        value = section.pop(old_key)
        target = dict(out.get(new_sec) or {})
        old, new = _key(old_sec, old_key, layer), _key(new_sec, new_key, layer)
        if new_key in target and target[new_key] != value:
            from anomalygen.errors import UserError

            raise UserError(f"{old} = {value!r} and {new} = {target[new_key]!r} in {layer}: {old} is the "
                             f"old name of {new}; keep only {new}")
        target[new_key] = value
        out[old_sec], out[new_sec] = section, target
        log.warning("%s (in %s) is read as %s, its new name: the plan stage has its own section now; "
                    "rename it", old, layer, new)
    return out


class _MovedKeys(PydanticBaseSettingsSource):
    """A settings source whose moved keys are read under their new names (``move_keys``)."""

    def __init__(self, settings_cls: type[BaseSettings], inner: PydanticBaseSettingsSource, layer: str):
        super().__init__(settings_cls)
        self.inner, self.layer = inner, layer

    def get_field_value(self, field, field_name):  # pragma: no cover - __call__ does the work
        return self.inner.get_field_value(field, field_name)

    def __call__(self) -> dict[str, Any]:
        return move_keys(self.inner(), self.layer)


# The TOML path of the load in progress: pydantic-settings builds sources in a classmethod with no
# per-call arguments, so ``load_settings`` hands the path over here for the duration of one load.
_CURRENT_TOML: dict[str, Path | None] = {"path": None}


def load_settings(config_file: str | Path | None = None, overrides: dict[str, Any] | None = None) -> Settings:
    """Build settings from an optional TOML file, the environment and explicit overrides (highest).

    ``overrides`` may use dotted keys (``{"llm.backend": "openai"}``); ``None`` values are ignored so
    CLI options that were not given do not mask lower layers.
    """
    path = Path(config_file) if config_file else None
    if path is not None:
        parse_config_file(path)  # a bad file is one line here; the settings source would skip a missing one
    nested = _nest({k: v for k, v in (overrides or {}).items() if v is not None})
    _CURRENT_TOML["path"] = path
    try:
        return Settings(**nested)  # pydantic-settings deep-merges the sources
    finally:
        _CURRENT_TOML["path"] = None


CONFIG_FILE = "config file"


def parse_config_file(path: Path) -> dict[str, Any]:
    """A ``--config`` TOML, read as text by ``anomalygen.textfile`` (the one reader of user files: a
    missing path, a folder, a binary file or text not in UTF-8 is one ``UserError`` line naming the
    file) and parsed; invalid TOML is one line with its line and column."""
    import tomllib

    from anomalygen.errors import UserError
    from anomalygen.textfile import read_text

    text = read_text(path, what=CONFIG_FILE)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise UserError(f"invalid TOML in {path}: {exc}") from None


class _ConfigFileSource(TomlConfigSettingsSource):
    """pydantic-settings' TOML source, reading the file with ``parse_config_file`` (so a UTF-8 file
    with a byte-order mark, which ``tomllib`` on the raw bytes refuses, reads the same both times)."""

    def _read_file(self, file_path) -> dict[str, Any]:
        return parse_config_file(Path(file_path))


def _nest(flat: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in flat.items():
        parts = key.split(".")
        node = out
        for part in parts[:-1]:
            node = node.setdefault(part, {})
        node[parts[-1]] = value
    return out
