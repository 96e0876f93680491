"""Scripted skills: motion primitives that need no learned policy (the scene says where to go),
registered as ``("primitive", action)`` in ``actions.py``."""
