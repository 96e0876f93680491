"""A count and its ratio: ``successes`` of ``n`` cases (truth hazards the detection found, runs whose
plan's own final condition held, sub-tasks a method solved).

Its own module because both the detection report and the evaluation record that embeds it count this
way, and ``results.py`` already imports ``detection_report.py``: the one model lives below both.

Run folders written before this model was shared hold the detection report's counts as ``hazards``
and ``found`` (``per_category`` of ``detections_summary.json`` and of ``evaluation.json``'s
``detection``); those names are still read, and ``n`` and ``successes`` are written.
"""

from __future__ import annotations

from pydantic import AliasChoices, Field

from anomalygen.schema import Strict


class Rate(Strict):
    n: int = Field(0, validation_alias=AliasChoices("n", "hazards"), description="cases counted")
    successes: int = Field(0, validation_alias=AliasChoices("successes", "found"), description="of those, the ones that came out well")

    @property
    def rate(self) -> float:
        return self.successes / self.n if self.n else 0.0
