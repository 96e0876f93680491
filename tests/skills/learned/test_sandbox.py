"""The reward sandbox: every case of the malicious/buggy corpus is stopped, valid code matches specs."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from anomalygen.schema import RewardSpec, RewardTerm
from anomalygen.skills.learned.reward import evaluate_spec, spec_to_code
from anomalygen.skills.learned.sandbox import RewardCodeError, SandboxedReward, check_code

CORPUS = json.loads((Path(__file__).parent / "data" / "bad_rewards.json").read_text())["cases"]


def _state(rng: np.random.Generator) -> dict:
    return {
        "ee": {"pos": rng.uniform(-1, 1, 3).tolist(), "quat": [1.0, 0.0, 0.0, 0.0]},
        "suction": 0.0,
        "objects": {
            "cup_0": {"pos": rng.uniform(-1, 1, 3).tolist(), "quat": (rng.normal(size=4) / 2).tolist(), "size": [0.1, 0.1, 0.12]},
            "cabinet_0:door": {"pos": rng.uniform(-1, 1, 3).tolist(), "quat": [1.0, 0.0, 0.0, 0.0], "size": [0.4, 0.02, 0.6]},
        },
        "joints": {"cabinet_0:door_hinge": float(rng.uniform(0, 1.5))},
        "regions": {"shelf": {"lo": [-0.2, -0.2, 0.0], "hi": [0.2, 0.2, 0.3]}},
        "action": rng.uniform(-1, 1, 7).tolist(),
    }


def test_corpus_is_large_enough():
    assert len(CORPUS) >= 30


@pytest.mark.parametrize("case", CORPUS, ids=[c["name"] for c in CORPUS])
def test_bad_reward_is_rejected_or_killed(case, tmp_path):
    marker = tmp_path / "escaped"
    code = case["code"].replace("@MARKER@", str(marker))
    state = _state(np.random.default_rng(0))
    stopped = False
    try:
        check_code(code)
    except RewardCodeError:
        stopped = True
    if not stopped:
        # The static check let it through: the run-time layer must stop it.
        with pytest.raises(RewardCodeError):
            with SandboxedReward(code, timeout_s=1.0) as fn:
                fn.dry_run(state)
    assert not marker.exists(), "reward code escaped the sandbox"


def test_runtime_layer_alone_stops_resource_attacks(tmp_path):
    """Code that passes the checker but loops, allocates or recurses is killed, not waited for."""
    import time

    for src in (
        "def compute_reward(state):\n    while True:\n        pass\n",
        "def compute_reward(state):\n    x = [0] * (10 ** 10)\n    return 0.0\n",
        "def f(n):\n    return f(n + 1)\n\ndef compute_reward(state):\n    return f(0)\n",
    ):
        check_code(src)
        t0 = time.perf_counter()
        with pytest.raises(RewardCodeError), SandboxedReward(src, timeout_s=1.0) as fn:
            fn({"x": 1})
        assert time.perf_counter() - t0 < 15


def test_state_is_read_only_in_the_sandbox():
    src = "def compute_reward(state):\n    d = state['joints']\n    d['x'] = 1.0\n    return 0.0\n"
    with pytest.raises(RewardCodeError, match="TypeError"), SandboxedReward(src) as fn:
        fn({"joints": {}})


SPECS = [
    RewardSpec(terms=[RewardTerm(kind="distance", a="ee", b="cup_0", scale=2.0), RewardTerm(kind="action_penalty", weight=0.01)]),
    RewardSpec(terms=[RewardTerm(kind="joint", joint="cabinet_0:door_hinge", target=0.0, weight=3.0)]),
    RewardSpec(terms=[RewardTerm(kind="inside", a="cup_0", b="shelf", scale=5.0), RewardTerm(kind="upright", a="cup_0")]),
    RewardSpec(terms=[RewardTerm(kind="lifted", a="cup_0", target=0.5), RewardTerm(kind="distance", a="cabinet_0:door", target=[0.1, 0.2, 0.3])]),
    RewardSpec(terms=[RewardTerm(kind="inside", a="ee", b="cabinet_0:door"), RewardTerm(kind="distance", a="ee", b="shelf")]),
]


@pytest.mark.parametrize("spec", SPECS)
def test_rendered_code_matches_spec(spec):
    rng = np.random.default_rng(1)
    states = [_state(rng) for _ in range(20)]
    # one state inside the shelf so the 'inside' branch with reward 1 is covered
    states[0]["objects"]["cup_0"]["pos"] = [0.0, 0.0, 0.1]
    with SandboxedReward(spec_to_code(spec)) as fn:
        for st in states:
            assert fn(st) == pytest.approx(evaluate_spec(spec, st), rel=1e-9, abs=1e-9)


def test_handwritten_code_matches_spec():
    spec = RewardSpec(terms=[RewardTerm(kind="joint", joint="cabinet_0:door_hinge", target=0.0), RewardTerm(kind="distance", a="ee", b="cabinet_0:door", scale=0.5)])
    code = (
        "def compute_reward(state):\n"
        "    q = state['joints']['cabinet_0:door_hinge']\n"
        "    d = np.norm(np.array(state['ee']['pos']) - np.array(state['objects']['cabinet_0:door']['pos']))\n"
        "    return -abs(q) - 0.5 * d\n"
    )
    rng = np.random.default_rng(2)
    with SandboxedReward(code) as fn:
        for _ in range(10):
            st = _state(rng)
            assert fn(st) == pytest.approx(evaluate_spec(spec, st))
