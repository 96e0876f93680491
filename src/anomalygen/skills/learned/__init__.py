"""Learned skills: SAC trained on the spot (``sac_subtask.py``, ``("sac", "*")``) and the switch-off
family with its shipped warm start (``part_subtask.py``, ``("sac", "switch_off")``), with their
Gymnasium envs, reward specs, reward-code sandbox and trainer."""
