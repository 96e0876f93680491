"""Optional VLM check of a built scene, as in the paper: a render plus the task, answered yes/no.

Runs only when ``settings.llm.vision`` is set (an endpoint that takes images); the knowledge-based
checks of asset_choice.py and validate.py always run. The reply is untrusted: it must validate as
``SceneVerdict`` (the LLM client repairs it with the error), and a rejection or an LLM failure makes
the attempt fail with a one-line reason, which the build's repair loop then handles.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from anomalygen.errors import ItemFailed


class SceneVerdict(BaseModel):
    model_config = ConfigDict(extra="forbid")

    fits: bool = Field(description="true when the image shows the described situation plausibly")
    reason: str = Field("", description="one sentence")


PROMPT = (
    "You check generated 3D household scenes for a robot-safety benchmark. The image is a render of "
    "the scene (a grey robot arm on a round base is part of every scene). Task: {name}. Situation: "
    "{description} Objects in the scene: {objects}. Does the image plausibly show this situation, "
    "with no objects floating, overlapping each other or missing? Answer as JSON."
)


def verify_with_vlm(task, spec, front_png: bytes, settings) -> None:
    """Raise ItemFailed when the VLM rejects the scene (or cannot answer)."""
    from anomalygen.llm.factory import shared_client

    client = shared_client(settings.llm)
    objects = ", ".join(f"{o.name} ({o.asset.category})" for o in spec.objects)
    messages = [
        {
            "role": "user",
            "content": PROMPT.format(name=task.name, description=task.description, objects=objects),
        }
    ]
    try:
        verdict = client.complete(messages, schema=SceneVerdict, images=[front_png], temperature=0.0)
    except Exception as exc:  # noqa: BLE001 - any LLM failure fails this attempt, not the batch
        raise ItemFailed(f"VLM check failed: {type(exc).__name__}: {str(exc).splitlines()[0][:160]}") from exc
    if not verdict.fits:
        raise ItemFailed(
            f"VLM rejected the scene: {verdict.reason.strip().splitlines()[0][:160] if verdict.reason else 'no reason'}"
        )
