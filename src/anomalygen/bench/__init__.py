"""Frozen suites and ``anomalygen bench``: any agent over a suite in the skill-level env, judged by the referee.

``suites.py``: the named suites, their reproducible build and manifest; ``run.py``: the episodes, as a
stage of a run folder; ``report.py``: the referee's table (JSON, HTML, terminal); ``cli.py``: the commands.
"""
