"""The names of the files in a scene folder (``scenes/<task_id>/``) and in a run's folder
(``skills/<task_id>/seed<k>/``): one owner, so that the builder that writes them, the robot's side
and the referee that read them, and the report cannot disagree about a name.

Which side may open which file is a rule of its own (``anomalygen.world.perception`` is the robot's
door); this module only names them.
"""

from __future__ import annotations

# scenes/<task_id>/
SCENE_XML = "scene.xml"  # the MJCF the simulator loads
SCENE_SPEC = "scene.json"  # SceneSpec: objects, joints, poses; written last, so its presence marks the scene done
SCENE_GRAPH = "scene_graph.json"  # SceneGraph of the settled initial state
TRUTH = "truth.json"  # HazardManifest: the hidden answer key (anomalygen.truth)
LLM_LAYOUT = "llm_layout.json"  # what an LLM scene engine said, before the builder's corrections
CONTACT_SHEET = "contact_sheet.png"  # in scenes/: every scene's front render on one sheet

# skills/<task_id>/seed<k>/
RESULT = "result.json"  # SkillResult: what the robot did and its own check
FINAL_STATE = "final_state.npz"  # the simulator state after the robot's last action
FINAL_GRAPH = "final_graph.json"  # the final state's scene graph as the robot perceives it (old runs: instead of FINAL_STATE)
VIDEO = "video.mp4"
VERDICT = "verdict.json"  # Verdict: the referee's judgement of the released, settled final state
JUDGED_GRAPH = "judged_graph.json"  # the released, settled final state's scene graph the verdict read
EPISODE = "episode.json"  # EpisodeRecord: an agent's calls in a bench run (anomalygen bench)

# a suite's folder (a run folder) and a bench run's folder
SUITE_MANIFEST = "suite.json"  # SuiteManifest: how the suite was built, a checksum of every scene
BENCH_REPORT = "bench.json"  # BenchReport: the referee's table of one agent on one suite
BENCH_PAGE = "bench.html"  # the same as a page


def render_file(camera: str) -> str:
    """A scene's render from one of its cameras (``front``, ``top``, ...)."""
    return f"render_{camera}.png"
