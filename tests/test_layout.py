"""The package layout's rules: imports form no cycles, counting imports inside functions and
type-checking-only imports too; no module is longer than MAX_LINES, except catalogues of generators;
no package imports one on its own floor or above (``FLOORS``); the robot's side reaches neither the
builder, the answer key nor the referee, not even through a shared module; the robot's element names
and controllers live in ``robot/`` only; the old homes of the skills are gone; the scene folder's file
names are spelled in one module."""

import ast
import re
from pathlib import Path

import anomalygen

ROOT = Path(anomalygen.__file__).parent
MAX_LINES = 500
# one generator function per vocabulary name: long, but a list, not a tangle
CATALOGUES = {"assets/generators/household.py", "assets/generators/furniture.py"}
# Packages from the bottom floor up. A module may import its own package and any package on a lower
# floor, never one on its own floor or above: the packages of one floor know nothing of each other.
FLOORS = (
    ("version", "errors", "rng", "tables", "procs", "embedding", "scene_files", "mjgeom", "schema"),
    ("textfile",),  # the one reader of user text files, below config and runfolder, which read them
    ("config", "knowledge", "robot"),
    ("llm", "runfolder"),
    ("assets", "runner", "truth"),  # truth: the answer key, which the builder writes and the referee reads
    ("world",),  # what a built scene is, as the robot perceives it
    ("scene", "skills", "detect", "plan", "referee"),  # the builder, the robot's side, the referee: apart
    ("learn", "evaluate"),
    ("brainstorm", "agents"),  # agents: the skill-level env and the baseline agents, on the robot's side
    ("stages",),  # the stage table
    ("pipeline", "bench"),  # bench: suites (built by the stages) and any agent over them, judged
    ("cli", ""),  # "": the package's own __init__ (make_env)
)
# The robot's side: it perceives the scene through the world package and acts on it.
ROBOT_SIDE = ("anomalygen.detect", "anomalygen.plan", "anomalygen.learn", "anomalygen.robot", "anomalygen.skills",
              "anomalygen.agents")
# What it may not reach, directly or through any module in between: the builder, the answer key, the
# referee, and what is built on them (the evaluation and report, the task generator and its words).
FORBIDDEN = ("anomalygen.scene", "anomalygen.truth", "anomalygen.referee", "anomalygen.evaluate",
             "anomalygen.brainstorm")

def _module_graph() -> dict[str, set[str]]:
    mods = {}
    for path in ROOT.rglob("*.py"):
        name = ".".join(path.relative_to(ROOT.parent).with_suffix("").parts)
        mods[name.removesuffix(".__init__")] = path
    edges: dict[str, set[str]] = {m: set() for m in mods}
    for name, path in mods.items():
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join(parts + ([base] if base else []))
                targets = [base] + [f"{base}.{a.name}" for a in node.names]
            else:
                continue
            edges[name] |= {t for t in targets if t in mods and t != name}
    return edges


def _cycles(edges: dict[str, set[str]]) -> list[set[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[set[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = set()
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.add(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(comp)

    for v in edges:
        if v not in index:
            visit(v)
    return found


def test_no_import_cycles():
    edges = _module_graph()
    # imports inside functions count: execute.py imports the skill catalogue inside _run_skill
    assert "anomalygen.skills.catalogue" in edges["anomalygen.learn.execute"]
    # so do type-checking-only ones: placement.py names Settings only in annotations
    assert "anomalygen.config" in edges["anomalygen.scene.placement"]
    cycles = _cycles(edges)
    assert cycles == [], f"import cycles: {[sorted(c) for c in cycles]}"


def test_the_checker_sees_a_cycle_made_inside_functions():
    assert _cycles({"a": {"b"}, "b": {"a"}, "c": set()}) == [{"a", "b"}]


def test_no_module_is_longer_than_the_limit():
    long = {
        path.relative_to(ROOT).as_posix(): n
        for path in ROOT.rglob("*.py")
        if (n := len(path.read_text().splitlines())) > MAX_LINES
    }
    assert {p: n for p, n in long.items() if p not in CATALOGUES} == {}


def _under(module: str, packages: tuple[str, ...]) -> bool:
    return any(module == p or module.startswith(p + ".") for p in packages)


def _forbidden_paths(edges: dict[str, set[str]], sources: tuple[str, ...], forbidden: tuple[str, ...]) -> list[list[str]]:
    """One shortest import path from each source module to a forbidden module it reaches, through
    any modules in between (imports inside functions count: they run when the function does)."""
    found = []
    for start in sorted(m for m in edges if _under(m, sources)):
        parent: dict[str, str | None] = {start: None}
        queue = [start]
        while queue:
            v = queue.pop(0)
            if _under(v, forbidden):
                path = [v]
                while parent[path[-1]] is not None:
                    path.append(parent[path[-1]])
                found.append(path[::-1])
                break
            for w in sorted(edges.get(v, ())):
                if w not in parent:
                    parent[w] = v
                    queue.append(w)
    return found


def _package(module: str) -> str:
    """The top-level package (or module) of ``anomalygen`` a module belongs to ("" for the root)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def _floor_of() -> dict[str, int]:
    return {pkg: i for i, floor in enumerate(FLOORS) for pkg in floor}


def _upward_imports(edges: dict[str, set[str]]) -> list[str]:
    floor = _floor_of()
    bad = []
    for src, targets in sorted(edges.items()):
        for dst in sorted(targets):
            a, b = _package(src), _package(dst)
            if a != b and dst != "anomalygen" and floor[b] >= floor[a]:
                bad.append(f"{src} -> {dst} (floor {floor[a]} imports floor {floor[b]})")
    return bad


def test_every_package_has_a_floor():
    assert {_package(m) for m in _module_graph()} == set(_floor_of())


def test_no_package_imports_one_on_its_own_floor_or_above():
    assert _upward_imports(_module_graph()) == []


def test_the_floor_check_sees_an_upward_import_and_one_between_neighbours():
    edges = {"anomalygen.world.graph": {"anomalygen.scene.build"}, "anomalygen.skills.x": {"anomalygen.referee.y"},
             "anomalygen.scene.build": {"anomalygen.world.graph"}, "anomalygen.referee.y": set()}
    floor = _floor_of()  # the numbers move when a floor is added below
    world, scene = floor["world"], floor["scene"]
    assert floor["skills"] == floor["referee"] == scene == world + 1
    assert _upward_imports(edges) == [
        f"anomalygen.skills.x -> anomalygen.referee.y (floor {scene} imports floor {scene})",
        f"anomalygen.world.graph -> anomalygen.scene.build (floor {world} imports floor {scene})"]


def test_the_robot_side_reaches_neither_the_builder_nor_the_answer_key_nor_the_referee():
    edges = _module_graph()
    robot = [m for m in edges if _under(m, ROBOT_SIDE)]
    assert "anomalygen.learn.stage" in robot and "anomalygen.detect.stage" in robot
    assert "anomalygen.agents.skill_env" in robot and "anomalygen.agents.pipeline" in robot
    # the answer-key side is real and reaches what it must: the builder writes truth.json, the referee reads it
    assert _forbidden_paths(edges, ("anomalygen.scene.build",), ("anomalygen.truth",))
    assert _forbidden_paths(edges, ("anomalygen.referee.stage",), ("anomalygen.truth",))
    paths = _forbidden_paths(edges, ROBOT_SIDE + ("anomalygen.world",), FORBIDDEN)
    assert paths == [], "robot side reaches the answer key: " + "; ".join(" -> ".join(p) for p in paths)


def test_the_reach_check_follows_imports_through_shared_modules():
    edges = {"anomalygen.plan.x": {"anomalygen.shared"}, "anomalygen.shared": {"anomalygen.truth.manifest"},
             "anomalygen.truth.manifest": set(), "anomalygen.detect.y": {"anomalygen.world.graph"},
             "anomalygen.world.graph": set()}
    assert _forbidden_paths(edges, ROBOT_SIDE, FORBIDDEN) == [
        ["anomalygen.plan.x", "anomalygen.shared", "anomalygen.truth.manifest"]]


SCRIPTED_SKILLS = ("anomalygen.skills.scripted",)
LEARNED_SKILLS = ("anomalygen.skills.learned",)


def test_scripted_skills_reach_no_learned_skill():
    """What scripted and learned skills both need (grasping a part, its readout, leading it, letting go,
    the reference action) lives below both, in ``skills/part_motion.py``: no module under
    ``skills/scripted`` imports one under ``skills/learned``, not inside a function either, nor through
    a module in between."""
    edges = _module_graph()
    # the switch-off primitive holds and leads a control through the shared module
    assert "anomalygen.skills.part_motion" in edges["anomalygen.skills.scripted.controls"]
    # and the learned skill does too (an import inside run_part_subtask, counted as any other)
    assert "anomalygen.skills.part_motion" in edges["anomalygen.skills.learned.part_subtask"]
    paths = _forbidden_paths(edges, SCRIPTED_SKILLS, LEARNED_SKILLS)
    assert paths == [], "scripted skills reach learned ones: " + "; ".join(" -> ".join(p) for p in paths)


def test_the_scripted_check_sees_an_import_of_a_learned_skill_direct_or_through_a_shared_module():
    edges = {"anomalygen.skills.scripted.a": {"anomalygen.skills.learned.x"},
             "anomalygen.skills.scripted.b": {"anomalygen.skills.shared"},
             "anomalygen.skills.shared": {"anomalygen.skills.learned.x"}, "anomalygen.skills.learned.x": set()}
    assert _forbidden_paths(edges, SCRIPTED_SKILLS, LEARNED_SKILLS) == [
        ["anomalygen.skills.scripted.a", "anomalygen.skills.learned.x"],
        ["anomalygen.skills.scripted.b", "anomalygen.skills.shared", "anomalygen.skills.learned.x"]]


def _string_constants(tree: ast.AST) -> list[str]:
    """Every string literal of a module, f-string pieces included."""
    return [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)]


def test_only_the_robot_package_names_robot_elements_or_drives_its_actuators():
    """The agent owns the element names and the controllers: no module outside ``robot/`` spells a
    distinctive element name (a Panda joint or link, the cup's geom and sites, the end-effector target
    and its weld, the suction weld prefix) or writes actuator gains (a control mode of its own)."""
    from anomalygen.robot.agent import Agent

    names = {*Agent.ROBOT_JOINTS, Agent.CUP_GEOM, Agent.CUP_SITE, Agent.EE_SITE, Agent.EE_TARGET, Agent.EE_TRACK,
             Agent.TORSO, Agent.SUCTION_PREFIX}
    spelled, driven = {}, {}
    for path in ROOT.rglob("*.py"):
        rel = path.relative_to(ROOT).as_posix()
        if rel.startswith("robot/"):
            continue
        tree = ast.parse(path.read_text())
        hits = {c for c in _string_constants(tree) if c in names or Agent.ARM_LINK_PREFIX + "joint" in c
                or Agent.ARM_LINK_PREFIX + "link" in c}
        if hits:
            spelled[rel] = sorted(hits)
        gains = {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute)
                 and n.attr in ("actuator_gainprm", "actuator_biasprm")}
        if gains:
            driven[rel] = sorted(gains)
    assert spelled == {} and driven == {}, (spelled, driven)


def test_the_checker_sees_an_element_name_spelled_out():
    tree = ast.parse('ARM = [f"panda_joint{i}" for i in range(1, 8)]\nCUP = "suction_site"')
    assert "suction_site" in _string_constants(tree)
    assert any("panda_joint" in c for c in _string_constants(tree))


def test_skills_have_one_home():
    """``control/`` and ``rl/`` are gone: scripted and learned skills live in ``skills/``, the motion
    layer in ``robot/``."""
    assert not (ROOT / "control").exists() and not (ROOT / "rl").exists()
    assert (ROOT / "robot" / "agent.py").is_file() and (ROOT / "skills" / "registry.py").is_file()


def test_the_scene_folders_file_names_are_spelled_in_one_module():
    """``scene_files`` owns every name of a scene's and a run's files: no other module spells one."""
    from anomalygen import scene_files

    names = {v for k, v in vars(scene_files).items() if k.isupper() and isinstance(v, str)}
    assert {"scene.json", "scene_graph.json", "truth.json", "verdict.json", "final_state.npz"} <= names
    spelled = {}
    for path in ROOT.rglob("*.py"):
        rel = path.relative_to(ROOT).as_posix()
        if rel == "scene_files.py":
            continue
        hits = {c for c in _string_constants(ast.parse(path.read_text())) if c in names}
        if hits:
            spelled[rel] = sorted(hits)
    assert spelled == {}


def test_no_module_takes_a_private_name_from_another_package():
    """A leading underscore is a package's own business: another package asks for a public function
    (the referee's settle once took the scene graph's ``_index``)."""
    taken = []
    for path in ROOT.rglob("*.py"):
        module = ".".join(path.relative_to(ROOT.parent).with_suffix("").parts)
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and not node.level and (node.module or "").startswith("anomalygen"):
                private = [a.name for a in node.names if a.name.startswith("_") and not a.name.startswith("__")]
                if private and _package(node.module) != _package(module):
                    taken.append(f"{module}: {node.module}.{', '.join(private)}")
    assert taken == []


def _placement_parsing(tree: ast.AST) -> list[str]:
    """What in a module reads a placement's compact form: a ``relation:`` prefix spelled out (also as
    the end of an f-string piece, ``f"inside:{name}"``), an edge suffix (``"_edge"``), or a string
    method (split, partition, startswith, ...) called on a value whose expression names a placement."""
    from anomalygen.schema import OBJECT_RELATIONS, RELATIONS

    prefixes = tuple(f"{r}:" for r in OBJECT_RELATIONS)
    ends = re.compile(rf"(?<![A-Za-z0-9_])({'|'.join(OBJECT_RELATIONS)}):$")  # "...inside:" but not "position:"
    pieces = {part for r in RELATIONS for part in r.word.split("{support}") if part and part != r.word}
    docstrings = {id(n.body[0].value) for n in ast.walk(tree)
                  if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and n.body
                  and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
    in_fstring = {id(v) for n in ast.walk(tree) if isinstance(n, ast.JoinedStr) for v in n.values}
    methods = {"split", "rsplit", "partition", "rpartition", "startswith", "endswith", "removeprefix"}
    hits = []
    for n in ast.walk(tree):
        if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docstrings:
            s = n.value
            if s.startswith(prefixes) or s in pieces or (id(n) in in_fstring and ends.search(s)):
                hits.append(repr(s))
        elif isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) and n.func.attr in methods \
                and "placement" in ast.unparse(n.func.value).lower():
            hits.append(ast.unparse(n))
    return hits


def test_placements_are_parsed_in_the_schema_only():
    """The compact placement words ("counter_edge", "inside:Bathtub") are read by ``schema/placement.py``
    alone; everywhere else reads the typed ``Placement``'s fields (relation, support, other)."""
    found = {}
    for path in ROOT.rglob("*.py"):
        rel = path.relative_to(ROOT).as_posix()
        if rel.startswith("schema/"):
            continue
        hits = _placement_parsing(ast.parse(path.read_text()))
        if hits:
            found[rel] = hits
    assert found == {}


def test_the_checker_sees_a_placement_parsed():
    src = ('def f(sc, name):\n    """near:Crib is fine in a docstring."""\n'
           '    a = sc.placement.split(":", 1)[1]\n    b = "inside:Bathtub"\n    c = f"on:{name}"\n'
           '    d = kind.replace("_edge", "")\n    return p.startswith("near:")\n')
    hits = _placement_parsing(ast.parse(src))
    assert len(hits) == 5 and not any("Crib" in h for h in hits), hits
