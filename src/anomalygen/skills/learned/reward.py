"""RewardSpec evaluation over a plain state dict, and rendering a spec as equivalent sandbox code.

The state dict is the one contract between the simulator and reward functions (spec or code), so
both can be tested without MuJoCo and the sandbox sees nothing but numbers::

    {"ee": {"pos": [x, y, z], "quat": [w, x, y, z]},
     "suction": 0.0 | 1.0,
     "objects": {"<instance>" | "<instance>:<body>": {"pos": [...], "quat": [...], "size": [...]}},
     "joints": {"<joint>": value},
     "regions": {"<name>": {"lo": [...], "hi": [...]}},
     "action": [...]}

Each term returns a value where larger is better; the reward is the weighted sum.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from anomalygen.schema import RewardSpec, RewardTerm


def position_of(state: Mapping[str, Any], ref: str | float | list[float] | None) -> np.ndarray:
    """A point: ``ee``, an object/link name, a region name (its centre), or a literal [x, y, z]."""
    if isinstance(ref, list | tuple | np.ndarray):
        return np.asarray(ref, dtype=float)
    if ref == "ee":
        return np.asarray(state["ee"]["pos"], dtype=float)
    if ref in state.get("objects", {}):
        return np.asarray(state["objects"][ref]["pos"], dtype=float)
    if ref in state.get("regions", {}):
        r = state["regions"][ref]
        return (np.asarray(r["lo"], dtype=float) + np.asarray(r["hi"], dtype=float)) / 2
    raise KeyError(f"unknown position reference {ref!r}")


def box_of(state: Mapping[str, Any], ref: str) -> tuple[np.ndarray, np.ndarray]:
    """An axis-aligned box: a named region, else an object's bounding box."""
    if ref in state.get("regions", {}):
        r = state["regions"][ref]
        return np.asarray(r["lo"], dtype=float), np.asarray(r["hi"], dtype=float)
    obj = state["objects"][ref]
    c, s = np.asarray(obj["pos"], dtype=float), np.asarray(obj["size"], dtype=float)
    return c - s / 2, c + s / 2


def term_value(term: RewardTerm, state: Mapping[str, Any]) -> float:
    """One term's value (before ``weight``)."""
    k, scale = term.kind, term.scale
    if k == "distance":
        other = term.b if term.b is not None else term.target
        d = np.linalg.norm(position_of(state, term.a) - position_of(state, other))
        return float(-scale * d)
    if k == "joint":
        q = float(state["joints"][term.joint or term.a])
        return float(-scale * abs(q - float(term.target)))
    if k == "inside":
        lo, hi = box_of(state, term.b)
        p = position_of(state, term.a)
        gap = np.linalg.norm(np.maximum(np.maximum(lo - p, p - hi), 0.0))
        return 1.0 if gap == 0.0 else float(-scale * gap)
    if k == "lifted":
        z = position_of(state, term.a)[2]
        return float(-scale * max(0.0, float(term.target) - z))
    if k == "upright":
        w, x, y, z = state["objects"][term.a]["quat"]
        return float(scale * (1.0 - 2.0 * (x * x + y * y)))
    if k == "action_penalty":
        a = np.asarray(state.get("action", []), dtype=float)
        return float(-scale * np.sum(a * a))
    raise ValueError(f"unknown reward term {k!r}")


def evaluate_spec(spec: RewardSpec, state: Mapping[str, Any]) -> float:
    """The weighted sum of the spec's terms (mode 'spec' only)."""
    if spec.mode != "spec":
        raise ValueError("evaluate_spec needs a RewardSpec in mode 'spec'")
    return float(sum(t.weight * term_value(t, state) for t in spec.terms))


def spec_to_code(spec: RewardSpec) -> str:
    """Render a spec as sandbox-valid ``compute_reward`` source that gives the same value.

    Used as the in-context example for LLM reward code, and to test the sandbox against the spec.
    """
    lines = [
        "def pos(state, ref):",
        "    if ref == 'ee':",
        "        return np.array(state['ee']['pos'])",
        "    if ref in state['objects']:",
        "        return np.array(state['objects'][ref]['pos'])",
        "    r = state['regions'][ref]",
        "    return (np.array(r['lo']) + np.array(r['hi'])) / 2",
        "",
        "def box(state, ref):",
        "    if ref in state['regions']:",
        "        return np.array(state['regions'][ref]['lo']), np.array(state['regions'][ref]['hi'])",
        "    c = np.array(state['objects'][ref]['pos'])",
        "    s = np.array(state['objects'][ref]['size'])",
        "    return c - s / 2, c + s / 2",
        "",
        "def compute_reward(state):",
        "    total = 0.0",
    ]
    for t in spec.terms:
        lines += [f"    {line}" for line in _TERM_CODE[t.kind](t, repr(float(t.scale)))]
        lines.append(f"    total = total + {float(t.weight)!r} * v")
    lines.append("    return float(total)")
    return "\n".join(lines) + "\n"


def _distance_code(t: RewardTerm, s: str) -> list[str]:
    b = f"pos(state, {t.b!r})" if t.b is not None else f"np.array({list(t.target)!r})"
    return [f"v = -{s} * np.norm(pos(state, {t.a!r}) - {b})"]


def _inside_code(t: RewardTerm, s: str) -> list[str]:
    return [f"lo, hi = box(state, {t.b!r})", f"p = pos(state, {t.a!r})",
            "gap = np.norm(np.maximum(np.maximum(lo - p, p - hi), 0.0))", f"v = 1.0 if gap == 0.0 else -{s} * gap"]


# Per term kind, the sandbox lines that set ``v`` to the term's value (``term_value`` in code).
_TERM_CODE = {
    "distance": _distance_code,
    "joint": lambda t, s: [f"v = -{s} * abs(state['joints'][{(t.joint or t.a)!r}] - {float(t.target)!r})"],
    "inside": _inside_code,
    "lifted": lambda t, s: [f"v = -{s} * max(0.0, {float(t.target)!r} - pos(state, {t.a!r})[2])"],
    "upright": lambda t, s: [f"q = state['objects'][{t.a!r}]['quat']", f"v = {s} * (1.0 - 2.0 * (q[1] * q[1] + q[2] * q[2]))"],
    "action_penalty": lambda t, s: [f"v = -{s} * float(np.sum(np.square(np.array(state['action']))))"],
}
