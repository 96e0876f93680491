"""The part-label table is the only place that spells a label the code decides by, and every module
that treats a part as a closure agrees with it (a shut cardboard box encloses what is in it)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import anomalygen
from anomalygen.schema import JointState, PartKind, part_labels

ROOT = Path(anomalygen.__file__).parent
TABLE_MODULE = "schema/part_labels.py"
# The labels the code decides by, and the words asset generators use for them.
DECIDING = {w for row in part_labels.TABLE if row.kind is not PartKind.OTHER for w in (row.name, *row.aliases)}
KNOWN = {w for row in part_labels.TABLE for w in (row.name, *row.aliases)}
# One string that equals a label but is not one: the plain-words description of the *category*
# Window (assets/describe.py), which names the whole object in a catalogue description.
NOT_A_LABEL = {("assets/describe.py", "window")}
SEEDS = 6  # variants generated per catalogue name when collecting the labels assets carry


def _is_label_literal(value: str) -> bool:
    """A deciding label, or a '|'-joined choice of labels with at least one deciding label."""
    words = value.split("|")
    return all(w in KNOWN for w in words) and any(w in DECIDING for w in words)


def _name_parameters() -> dict[str, list[str]]:
    """Parameter names of the asset-building functions (``Part.child``, the parts library, the
    generators' helpers), without ``self``: a string passed as a ``name`` there names a body."""
    out: dict[str, list[str]] = {}
    for path in (ROOT / "assets").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef):
                out[node.name] = [a.arg for a in node.args.args if a.arg != "self"]
    return out


def _body_names(tree: ast.AST, params: dict[str, list[str]]) -> set[int]:
    """ids of the string constants passed as the ``name`` of a part or a parts-library builder:
    a lid's body is called "lid" because that is what it is; its joint's label is declared apart."""
    out: set[int] = set()
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        fn = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", None)
        names = params.get(fn)
        if not names or "name" not in names:
            continue
        at = names.index("name")
        if at < len(node.args):
            out.add(id(node.args[at]))
        out |= {id(k.value) for k in node.keywords if k.arg == "name"}
    return out


def _label_literals() -> list[str]:
    params = _name_parameters()
    found = []
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        if rel == TABLE_MODULE:
            continue
        tree = ast.parse(path.read_text())
        docstrings = {id(n.value) for n in ast.walk(tree) if isinstance(n, ast.Expr)}
        bodies = _body_names(tree, params) if rel.startswith("assets/") else set()
        for node in ast.walk(tree):
            if not (isinstance(node, ast.Constant) and isinstance(node.value, str)):
                continue
            if id(node) in docstrings or id(node) in bodies or (rel, node.value) in NOT_A_LABEL:
                continue
            if _is_label_literal(node.value):
                found.append(f"{rel}:{node.lineno}: {node.value!r}")
    return found


def test_no_module_outside_the_table_spells_a_part_label():
    found = _label_literals()
    assert not found, "use the constants and functions of anomalygen.schema.part_labels:\n" + "\n".join(found)


def test_the_scan_catches_a_literal_copy(tmp_path, monkeypatch):
    """The scan is not vacuous: a module comparing a label with a literal, or building a choice of
    labels by hand, is reported; a body named after its part is not."""
    pkg = tmp_path / "anomalygen"
    (pkg / "assets").mkdir(parents=True)
    (pkg / "plan.py").write_text('OK = ("flap", "door")\nX = "lid|flap"\ny = "switch"\n')
    (pkg / "assets" / "gen.py").write_text(
        'def child(self, name, label=""):\n    pass\n\nlid = r.child("lid")\nlid.hinge("h", "lid")\n')
    monkeypatch.setattr(f"{__name__}.ROOT", pkg)
    found = _label_literals()
    assert sorted(found) == ["assets/gen.py:5: 'lid'", "plan.py:1: 'door'", "plan.py:1: 'flap'",
                             "plan.py:2: 'lid|flap'", "plan.py:3: 'switch'"]


def test_every_closure_the_planner_and_skills_use_is_enclosing_in_the_table_and_the_graph():
    from anomalygen.plan import planner
    from anomalygen.schema import shut_by
    from anomalygen.skills.scripted import access, joints
    from anomalygen.world.graph import cavity_closers

    used = {*planner.CLOSURES, *planner.LID_PARTS.split("|"), *access.CLOSURES_ALL, *access.LIDS,
            *joints.ACCESS_LABELS}
    assert part_labels.FLAP in used
    for label in used:
        assert part_labels.encloses(label) and part_labels.is_closure(label), label
        # the graph: a cavity that names this part (and a second leaf no cavity names) is shut by both
        leaves = [JointState(name=f"{label}_{i}", label=label, value=0.0, range=(0.0, 1.5), closed_value=0.0)
                  for i in range(2)]
        (closers,) = cavity_closers(leaves, [leaves[0].name])
        assert {js.name for js in closers} == {js.name for js in leaves}, label
        assert shut_by([(js, 0.0) for js in closers]), label
        assert not shut_by([(js, 0.5 if js is leaves[1] else 0.0) for js in closers]), label
    # a part that does not enclose (an oven rack's slide, a window) leaves a cavity to the enclosing ones
    rack = JointState(name="rack", label="rack", value=0.0, range=(0.0, 0.3), closed_value=0.0)
    flap = JointState(name="flap_0", label=part_labels.FLAP, value=0.0, range=(0.0, 1.5), closed_value=0.0)
    assert [[js.name for js in c] for c in cavity_closers([rack, flap], ["rack", None])] == [["flap_0"], ["flap_0"]]
    assert cavity_closers([rack], ["rack"]) == [[]] and not shut_by([])
    # and the table's views are the same sets
    assert set(part_labels.ENCLOSING_LABELS) == used
    assert set(part_labels.LID_LABELS) == {part_labels.LID, part_labels.FLAP}


def test_the_table_answers_for_labels_aliases_and_imported_compounds():
    pl = part_labels
    assert [pl.canonical(w) for w in ("sash", "button", "dial", "flap", "rotation_door", "blade", "part")] == [
        "window", "switch", "knob", "flap", "door", "blade", "part"]
    assert pl.encloses("flap") and pl.swings("flap") and pl.part_label("flap").lid_like
    assert pl.is_closure("window") and not pl.encloses("window") and pl.swings("sash")
    assert not pl.swings("drawer") and pl.encloses("drawer")
    assert all(pl.is_switch(w) for w in ("knob", "dial", "switch", "button", "tap")) and not pl.is_switch("door")
    assert pl.kind_of("wheel") is PartKind.OTHER and pl.kind_of("never_heard_of") is PartKind.OTHER
    assert not pl.encloses("slide")  # a substring is not a label (the old check found "lid" in it)
    assert pl.any_of(pl.LID_LABELS) == "lid|flap" and pl.alternatives(" lid| flap ") == ["lid", "flap"]
    assert pl.ENCLOSING_LABELS == ("lid", "flap", "drawer", "door")  # the order plans list them in
    assert set(pl.CLOSURE_LABELS) == {"lid", "flap", "drawer", "door", "window", "sash", "gate"}


@pytest.mark.parametrize(("label", "value", "off"), [("knob", 0.0, True), ("knob", 0.1, False), ("switch", 0.05, True)])
def test_is_off_is_closed_for_a_switch(label, value, off):
    js = JointState(name="k", label=label, value=value, range=(0.0, 1.0), closed_value=0.0)
    assert js.is_switch and js.is_off() is off and js.is_closed() is off


def test_every_label_the_catalogue_and_knowledge_base_use_has_a_row():
    """A new label gets a kind here, or no rule of the code knows whether it shuts or switches."""
    from anomalygen.assets.core import available_names, generate
    from anomalygen.knowledge import load_kb

    kb = load_kb()
    kb_labels = {p.label for o in kb.objects.values() for p in o.parts}
    for hc in kb.hazard_classes.values():
        args = [c.args for c in (*hc.preconditions, *hc.success, *hc.recipe)]
        written = [a["label"] for a in args if "label" in a] + ([hc.articulation.part] if hc.articulation else [])
        kb_labels |= {w for x in written for w in part_labels.alternatives(x) if w != "*"}
    # a generator's parts vary with the seed (a box has a lid or, cardboard, two flaps)
    asset_labels = {j.label for name in available_names() for seed in range(SEEDS) for j in generate(name, seed).joints}
    unknown = sorted(w for w in kb_labels | asset_labels if part_labels.part_label(w) is None)
    assert not unknown, unknown
