"""What the LLM-backed detectors share: the client, the knowledge base, the sampling settings, and one
request of a system and a user message for a reply schema."""

from __future__ import annotations

from pydantic import BaseModel


class AskingDetector:
    def __init__(self, client, kb=None, *, temperature: float | None = 0.0, seed: int | None = 0):
        self.client = client
        self.kb = kb
        self.temperature = temperature
        self.seed = seed

    def ask(self, system: str, user: str, schema: type[BaseModel]) -> BaseModel:
        """The validated reply (raises ``LLMItemError`` like the client)."""
        return self.client.complete(
            [{"role": "system", "content": system}, {"role": "user", "content": user}],
            schema=schema,
            temperature=self.temperature,
            seed=self.seed,
        )
