"""plan stage: decompose each fix into sub-tasks (knowledge base or LLM)."""
