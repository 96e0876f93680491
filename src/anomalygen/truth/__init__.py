"""The answer key: every hazard a built scene holds, bound to its instances, and its near-misses.

A neutral home between the two sides that must not meet: the builder (``anomalygen.scene``) writes
each scene's hidden ``truth.json`` here, and the referee (``anomalygen.referee``) reads it to judge.
The robot's side (detect, plan, learn, skills, robot) never imports this package, and a layout test
walks the import graph to keep it so.
"""

from anomalygen.truth.manifest import hazard_manifest, load_manifest

__all__ = ["hazard_manifest", "load_manifest"]
