"""Reading a packaged model's MJCF fragments into one standalone ``MjSpec``.

Packaged models come in pieces: an asset file (meshes, materials, defaults, its own ``<compiler>``)
and a body file (the kinematic tree), with relative mesh paths that only resolve from the package's
own top-level scene. Here the pieces are merged into one document under a body named ``root``, every
mesh path is made absolute (resolved now, from the installed package: no path of this machine is ever
written into a committed file), and image textures are dropped: a 1024-pixel wood texture costs more
in software rendering than it adds to a 320x240 scene render, so a textured material gets the
texture's mean colour instead (measured once per texture file, ``TEXTURE_COLOURS``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

# Mean RGB of each texture image the packaged models use (PIL, whole image, 0..1): the colour a
# material keeps when its texture is dropped (multiplied by the material's own rgba, as MuJoCo does).
TEXTURE_COLOURS = {
    "metal1.png": (0.52, 0.52, 0.51),
    "wood1.png": (0.68, 0.45, 0.28),
    "marble1.png": (0.81, 0.81, 0.81),
    "tile1.png": (0.23, 0.43, 0.48),
    "stone0.png": (0.81, 0.81, 0.81),
    "stone1.png": (0.88, 0.92, 0.94),
}
# elements of an asset fragment that become top-level sections of the merged document
_SECTIONS = ("default", "equality", "contact", "tendon")


class PackageFileMissing(RuntimeError):
    """A file the model needs is not in the installed package (a different package version)."""


@dataclass(frozen=True)
class Fragments:
    """The files one packaged model is made of."""

    assets: tuple[Path, ...]  # <asset>, <default>, <compiler>, <equality> ...
    bodies: tuple[Path, ...]  # top-level elements go inside the ``root`` body
    mesh_base: Path  # the folder the asset files' relative mesh paths are written against
    texture_dir: Path | None = None  # where texture files live (their mean colour is looked up by name)
    compiler: dict[str, str] = field(default_factory=dict)  # attributes set on the merged <compiler>


def package_dir(module: str) -> Path:
    """Where an installed package's files are, found without importing it (gymnasium-robotics
    warns and takes two seconds on import)."""
    import importlib.util

    found = importlib.util.find_spec(module)
    if found is None or not found.submodule_search_locations:
        raise PackageFileMissing(f"the package providing {module!r} is not installed")
    return Path(list(found.submodule_search_locations)[0]).resolve()


def _read(path: Path) -> ET.Element:
    if not path.is_file():
        raise PackageFileMissing(f"{path.name} is missing from the installed package ({path.parent})")
    return ET.parse(path).getroot()


def _colour_of(texture: ET.Element) -> tuple[float, float, float]:
    name = Path(texture.get("file", "")).name
    if name not in TEXTURE_COLOURS:
        raise PackageFileMissing(f"texture {name!r} has no recorded mean colour (TEXTURE_COLOURS)")
    return TEXTURE_COLOURS[name]


def _untextured(material: ET.Element, textures: dict[str, tuple[float, float, float]]) -> ET.Element:
    tex = material.attrib.pop("texture", None)
    if tex is not None:
        rgba = [float(v) for v in material.get("rgba", "1 1 1 1").split()]
        mean = textures.get(tex, (1.0, 1.0, 1.0))
        rgba[:3] = [round(a * b, 3) for a, b in zip(rgba[:3], mean, strict=True)]
        material.set("rgba", " ".join(f"{v:g}" for v in rgba))
        for key in ("texrepeat", "texuniform"):
            material.attrib.pop(key, None)
    return material


def merge(fr: Fragments, edit: Callable[[ET.Element], None] | None = None) -> str:
    """One MJCF document: compiler, assets (absolute mesh paths, no textures), defaults, the bodies
    under ``root``. ``edit`` may change the merged tree before it is written (drop or move parts)."""
    doc = ET.Element("mujoco", model="packaged")
    compiler = ET.SubElement(doc, "compiler", angle="radian", autolimits="true")
    asset = ET.SubElement(doc, "asset")
    sections: dict[str, ET.Element] = {}
    textures: dict[str, tuple[float, float, float]] = {}
    materials: list[ET.Element] = []
    for path in fr.assets:
        src = _read(path)
        for comp in src.iter("compiler"):
            for k, v in comp.attrib.items():
                if k not in ("meshdir", "texturedir", "angle"):
                    compiler.set(k, v)
        for block in src.findall("asset"):
            for el in block:
                if el.tag == "mesh":
                    file = (fr.mesh_base / el.get("file", "")).resolve()
                    if not file.is_file():
                        raise PackageFileMissing(f"mesh {file.name} is missing from the installed package")
                    el.set("file", str(file))
                    asset.append(el)
                elif el.tag == "texture":
                    textures[el.get("name", "")] = _colour_of(el)
                elif el.tag == "material":
                    materials.append(el)
                else:
                    asset.append(el)
        for tag in _SECTIONS:
            for el in src.findall(tag):
                if tag == "default":
                    doc.append(el)
                else:
                    sections.setdefault(tag, ET.Element(tag)).extend(list(el))
    for m in materials:
        asset.append(_untextured(m, textures))
    for k, v in fr.compiler.items():
        compiler.set(k, v)
    world = ET.SubElement(doc, "worldbody")
    root = ET.SubElement(world, "body", name="root")
    for path in fr.bodies:
        root.extend(list(_read(path)))
    for el in sections.values():
        if len(el):
            doc.append(el)
    if edit is not None:
        edit(doc)
    return ET.tostring(doc, encoding="unicode")


def load_spec(fr: Fragments, edit: Callable[[ET.Element], None] | None = None):
    """The merged fragments as an ``MjSpec`` (the source's own compiler settings still in force)."""
    import mujoco

    return mujoco.MjSpec.from_string(merge(fr, edit))


def find(doc: ET.Element, tag: str, name: str) -> ET.Element:
    """The element ``<tag name=name>`` anywhere in the tree (KeyError naming it if absent)."""
    for el in doc.iter(tag):
        if el.get("name") == name:
            return el
    raise KeyError(f"no <{tag} name={name!r}> in the packaged model")


def remove(doc: ET.Element, tag: str, name: str) -> ET.Element:
    """Detach ``<tag name=name>`` from its parent and return it."""
    target = find(doc, tag, name)
    for parent in doc.iter():
        if target in list(parent):
            parent.remove(target)
            return target
    raise KeyError(name)  # pragma: no cover - find() found it, so a parent holds it
