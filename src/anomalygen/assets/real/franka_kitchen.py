"""Franka Kitchen models from ``gymnasium-robotics`` (Apache-2.0 XMLs, Google LLC): the microwave,
the two-door and the sliding-door wall cabinets, the kettle and the range, rebuilt as a stove.

Each loader merges the item's ``*_asset.xml`` and ``*_chain.xml`` (``mjcf.merge``), renames its
moving parts to the project's names, and declares what the catalogue needs: joint labels and closed
values, cavities and surfaces (source frame, metres, front -y as in the Franka Kitchen), the handle
and burner geoms. Collision geoms are the sources' group-4 boxes and capsules.

The Franka Kitchen range carries its four knobs on a box under the extractor hood, 60 cm above the
burners; its oven door does not move. The stove here keeps the range (body, oven window, handles,
cooktop, the four burner plates) and mounts the four knobs on the range's front band under the
cooktop, where a cooker's knobs are (and where a child reaches them); the hood, its light and light
switch are left out. Each knob is bound to the burner it controlled in the source (``parts``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from anomalygen.assets.generators.parts_lib import GLOW
from anomalygen.assets.model import Cavity, Surface
from anomalygen.assets.real.convert import Raw
from anomalygen.assets.real.mjcf import Fragments, find, load_spec, package_dir, remove
from anomalygen.schema.part_labels import DOOR, KNOB

COLLISION_GROUP = 4  # the Franka Kitchen's collision geoms
PACKAGE = "gymnasium-robotics"
LICENCE = "Apache-2.0"


def kitchen_dir() -> Path:
    return package_dir("gymnasium_robotics") / "envs" / "assets" / "kitchen_franka" / "kitchen_assets"


def _fragments(item: str) -> Fragments:
    base = kitchen_dir() / "item_assets"
    return Fragments(
        assets=(base / f"{item}_asset.xml",),
        bodies=(base / f"{item}_chain.xml",),
        mesh_base=base,
        # the source counts group-4 (collision) geoms only for masses; keep that for the first compile
        compiler={"inertiagrouprange": f"{COLLISION_GROUP} {COLLISION_GROUP}", "inertiafromgeom": "auto"},
    )


def _rename(doc: ET.Element, tag: str, old: str, new: str) -> ET.Element:
    el = find(doc, tag, old)
    el.set("name", new)
    return el


def _moving_part(doc: ET.Element, body: str, name: str, joint: str, joint_name: str,
                 geoms: dict[int, str] | None = None) -> ET.Element:
    """Rename a moving part and its joint, name some of its geoms (by position: the sources leave
    them unnamed) and drop its sites (the source robot's targets)."""
    part = _rename(doc, "body", body, name)
    _rename(doc, "joint", joint, joint_name)
    found = part.findall("geom")
    for i, geom_name in (geoms or {}).items():
        found[i].set("name", geom_name)
    for site in part.findall("site"):
        part.remove(site)
    return part


# ----------------------------------------------------------------------------- microwave

def microwave() -> Raw:
    def edit(doc: ET.Element) -> None:
        _rename(doc, "body", "microroot", "carcass")
        # geoms 2-4 are the visual handle bar and its two posts, 5-7 their collision capsules
        _moving_part(doc, "microdoorroot", "door", "microwave", "door_hinge", {2: "handle_bar", 5: "handle_bar_col"})

    spec = load_spec(_fragments("microwave"), edit)
    # interior between the collision walls (left wall x -0.287, control panel x 0.127, back y 0.161,
    # floor z 0.048, ceiling z 0.336; the door closes the front at y -0.176), 2 mm in from each
    return Raw(
        spec=spec,
        joints={"door_hinge": (DOOR, 0.0)},
        collision_group=COLLISION_GROUP,
        cavities=[Cavity("oven_space", (-0.08, -0.0075, 0.192), (0.205, 0.1665, 0.142), "front", "door_hinge")],
        surfaces=[Surface("top", (-0.08, 0.0, 0.374), (0.25, 0.15))],
        parts={DOOR: [DOOR], "handle": ["handle_bar", "handle_bar_col"]},
        features=["black with a glass window", "side-hinged door with a bar handle", "control panel"],
    )


# ----------------------------------------------------------------------------- cabinets

def hinge_cabinet() -> Raw:
    def edit(doc: ET.Element) -> None:
        _rename(doc, "body", "hingecab", "carcass")
        for side, source_body in (("left", "hingeleftdoor"), ("right", "hingerightdoor")):
            _moving_part(doc, source_body, f"{side}_door", f"{side}_hinge_cabinet", f"{side}_door_hinge",
                         {0: f"{side}_handle_bar"})

    spec = load_spec(_fragments("hingecabinet"), edit)
    # two compartments either side of the 8 cm middle wall: x 0.04..0.36, y -0.30..0.26, z -0.16..0.16
    half = (0.15, 0.27, 0.15)
    return Raw(
        spec=spec,
        joints={"left_door_hinge": (DOOR, 0.0), "right_door_hinge": (DOOR, 0.0)},
        collision_group=COLLISION_GROUP,
        cavities=[
            Cavity("left_compartment", (-0.2, -0.02, 0.0), half, "front", "left_door_hinge"),
            Cavity("right_compartment", (0.2, -0.02, 0.0), half, "front", "right_door_hinge"),
        ],
        surfaces=[Surface("top", (0.0, 0.0, 0.2), (0.38, 0.28))],
        parts={DOOR: ["left_door", "right_door"], "handle": ["left_handle_bar", "right_handle_bar"]},
        features=["blue-grey", "two doors with bar handles"],
    )


def slide_cabinet() -> Raw:
    def edit(doc: ET.Element) -> None:
        _rename(doc, "body", "slide", "carcass")
        _moving_part(doc, "slidelink", "door", "slide_cabinet", "door_slide", {2: "handle_bar"})

    spec = load_spec(_fragments("slidecabinet"), edit)
    # the left half is the compartment (x -0.404..-0.002, y -0.3..0.252, z -0.16..0.16); the sliding
    # door covers it when shut and slides over the solid right half to open it
    return Raw(
        spec=spec,
        joints={"door_slide": (DOOR, 0.0)},
        collision_group=COLLISION_GROUP,
        cavities=[Cavity("compartment", (-0.203, -0.024, 0.0), (0.19, 0.266, 0.15), "front", "door_slide")],
        surfaces=[Surface("top", (0.0, 0.0, 0.2), (0.43, 0.28))],
        parts={DOOR: [DOOR], "handle": ["handle_bar"]},
        features=["blue-grey", "one sliding door with a bar handle"],
    )


# ----------------------------------------------------------------------------- kettle

def kettle() -> Raw:
    def edit(doc: ET.Element) -> None:
        body = _rename(doc, "body", "kettleroot", "body")
        for site in body.findall("site"):
            body.remove(site)

    return Raw(
        spec=load_spec(_fragments("kettle"), edit),
        joints={},
        collision_group=COLLISION_GROUP,
        parts={"handle": []},
        features=["white enamel stovetop kettle", "arched wooden handle"],
    )


# ----------------------------------------------------------------------------- stove

# (knob, burner it controlled in the source, its x on the front band): left-to-right in the same
# order as the burners they light (back-left, front-left, front-right, back-right)
_KNOBS = (("knob 4", "Burner 4", -0.347), ("knob 2", "Burner 2", -0.137), ("knob 1", "Burner 1", 0.103),
          ("knob 3", "Burner 3", 0.313))  # 0.12 and 0.33 either side of the band's middle (x -0.017)
_BAND_FRONT_Y = -0.342  # the front face of the range's band under the cooktop (ovenroot frame)
_BAND_Z = 0.455  # its middle height
_BURNER_RGBA = "0.22 0.07 0.05 1"  # a cold element: dark red-brown
_GLOW_RADIUS = 0.09  # m, a little inside the burner ring
_GLOW_HALF_HEIGHT = 0.004  # m
_GLOW_LIFT = 0.008  # m above the burner geom's centre, so the disc shows over its top face
_GLOW_RGBA = " ".join(f"{v:g}" for v in GLOW)  # the procedural burners' glow, hidden until lit
# A cooker knob turns stiffly. A free one (damped in proportion to its 60 g cm^2 inertia, like a
# procedural part) was still spinning at 33 rad/s when the suction cup let go of it at off, and
# coasted 0.3 rad back on; dry friction alone is too soft a constraint on so small an inertia.
KNOB_DAMPING = 0.2  # N m s/rad: 0.6 N m against a hand turning it at 3 rad/s
KNOB_FRICTION = 0.1  # N m


def _glow(control: str, burner_pos: str) -> ET.Element:
    """A hidden disc just over a burner, named after the knob that lights it: the builder shows it
    while that knob is on (``world/states.py``), as the procedural stove's burners glow."""
    x, y, z = (float(v) for v in burner_pos.split())
    return ET.Element("geom", {
        "name": f"{control}_glow", "type": "cylinder", "size": f"{_GLOW_RADIUS} {_GLOW_HALF_HEIGHT}",
        "pos": f"{x} {y} {z + _GLOW_LIFT}", "rgba": _GLOW_RGBA, "contype": "0", "conaffinity": "0",
        "group": "1", "mass": "0"})


def stove() -> Raw:
    names: dict[str, str] = {}

    def edit(doc: ET.Element) -> None:
        root = find(doc, "body", "root")
        for light in list(root.findall("light")):
            root.remove(light)
        remove(doc, "body", "hoodroot")
        for el in list(doc.findall("equality")):
            doc.remove(el)
        oven = _rename(doc, "body", "ovenroot", "range")
        for i, (knob, burner, x) in enumerate(_KNOBS, start=1):
            b = remove(doc, "body", burner)
            geom = b.find("geom")
            geom.set("name", f"burner_{i}")
            geom.set("pos", b.get("pos"))
            geom.attrib.pop("material", None)
            geom.set("rgba", _BURNER_RGBA)
            oven.append(geom)
            oven.append(_glow(f"knob_{i}", b.get("pos")))
            k = _moving_part(doc, knob, f"knob_{i}", f"knob_Joint_{knob.split()[1]}", f"knob_{i}_joint")
            k.set("pos", f"{x} {_BAND_FRONT_Y} {_BAND_Z}")
            names[f"knob_{i}_joint"] = f"burner_{i}"
        for i in range(1, 5):  # knobs in the order of their names, left to right
            k = find(doc, "body", f"knob_{i}")
            oven.remove(k)
            oven.append(k)

    spec = load_spec(_fragments("oven"), edit)
    top = 0.635  # the range's collision box top (ovenroot frame), what a pot stands on
    burners = {"burner_1": (-0.237, 0.322), "burner_2": (-0.24, -0.119), "burner_3": (0.206, -0.119),
               "burner_4": (0.204, 0.322)}
    # the range body sits at ovenroot (0.115, -0.2921, 0.9834) in its chain file
    ox, oy, oz = 0.115, -0.2921, 0.9834
    return Raw(
        spec=spec,
        # FK knobs turn from 0 (off) to -1.57 (full on)
        joints={f"knob_{i}_joint": (KNOB, 0.0) for i in range(1, 5)},
        collision_group=COLLISION_GROUP,
        surfaces=[Surface("cooktop", (ox - 0.017, oy + 0.1, oz + top), (0.46, 0.42))]
        + [Surface(n, (ox + x, oy + y, oz + top), (0.1, 0.1)) for n, (x, y) in burners.items()],
        parts={KNOB: [f"knob_{i}" for i in range(1, 5)], "burner": list(burners),
               "knob_burner": [[k, b] for k, b in sorted(names.items())]},
        features=["white range with an oven window", "four burners on a black cooktop",
                  "four control knobs on the front"],
        front=(0.0, -1.0),  # the knobs: it stands square to the room with them towards the robot
        resistance={f"knob_{i}_joint": (KNOB_DAMPING, KNOB_FRICTION) for i in range(1, 5)},
    )
