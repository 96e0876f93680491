"""The robot's skills, one registry keyed by (method, action) (``registry.py``; ``catalogue.py`` loads
every skill): scripted ones in ``scripted/``, learned ones (SAC, with their envs, rewards and trainer)
in ``learned/``. Every skill runs in an ``Episode`` (``episode.py``): the scene, the robot, what
skills remember between sub-tasks, the step budget and the video. Scene queries: ``geometry.py``."""
