"""The Asset interface every stage consumes, and a generator's draft of one.

An Asset is a standalone ``mujoco.MjSpec`` (compiler in radians) whose worldbody holds exactly one body
named ``root`` with no free joint, plus the facts other stages need without compiling anything:
bounding box (bottom at z = 0, centred in x/y), mass, labelled joints with their safe values, support
surfaces and cavities, and a retrieval description. The scene builder decides whether root gets a
free joint (loose objects) or stays welded (furniture).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from anomalygen.assets.parts import Part
from anomalygen.schema import AssetRef, AssetSource


@dataclass(frozen=True)
class AssetJoint:
    name: str  # unprefixed joint name in the asset spec
    type: str  # hinge | slide
    range: tuple[float, float]  # radians or metres
    label: str  # door, drawer, lid, knob, handle, button, blade, wheel, rotor, seat, pedal, sash, ...
    closed_value: float  # the safe / closed state
    axis: tuple[float, float, float]
    body: str = ""  # unprefixed name of the moving body


@dataclass(frozen=True)
class Surface:
    """A place things can rest on: top height ``center[2]``, rectangle half sizes in x, y."""

    name: str
    center: tuple[float, float, float]
    half_size: tuple[float, float]


@dataclass(frozen=True)
class Cavity:
    """An interior that can hold objects; ``joint`` closes it (None when always open)."""

    name: str
    center: tuple[float, float, float]
    half_extents: tuple[float, float, float]
    opening: str  # top | front
    joint: str | None = None
    # nothing closes it and what lies in it may rise above the rim (a sink's basin, a crib): its
    # depth does not bound what fits, only its floor does
    open_above: bool = False


@dataclass
class Draft:
    """What a generator returns: geometry at a nominal size plus the semantic extras."""

    root: Part
    params: dict[str, Any] = field(default_factory=dict)
    surfaces: list[Surface] = field(default_factory=list)
    cavities: list[Cavity] = field(default_factory=list)
    features: list[str] = field(default_factory=list)  # words for the description: "two doors", "red"
    front_access: bool = False  # reached from its front (-y): a bookcase's shelves, a stove's knobs


@dataclass
class Asset:
    asset_id: str
    name: str
    category: str
    source: AssetSource
    seed: int | None
    spec: Any  # mujoco.MjSpec
    aabb: tuple[np.ndarray, np.ndarray]
    mass: float
    joints: list[AssetJoint]
    surfaces: list[Surface]
    cavities: list[Cavity]
    description: str
    params: dict[str, Any] = field(default_factory=dict)
    path: str | None = None
    features: list[str] = field(default_factory=list)  # the generator's words for this variant
    # its surfaces or controls are reached from its front (-y) only, so the builder turns that side to
    # the robot (a bookcase's shelves, a stove's knobs); doors, drawers and cavities imply it already
    front_access: bool = False
    package: str | None = None  # the installed package a real model comes from (None: procedural)
    licence: str | None = None  # SPDX licence of that model's files
    # the side it is worked from, when no door, drawer or cavity says so (a stove's knobs): (0, -1)
    front: tuple[float, float] | None = None
    _keep: list = field(default_factory=list, repr=False)

    @property
    def size(self) -> float:
        """Largest dimension in metres."""
        return float(np.max(self.aabb[1] - self.aabb[0]))

    @property
    def ref(self) -> AssetRef:
        return AssetRef(
            asset_id=self.asset_id,
            category=self.category,
            source=self.source,
            seed=self.seed,
            params=dict(self.params),
            path=self.path,
            package=self.package,
            licence=self.licence,
        )

    def root_body(self):
        return self.spec.worldbody.first_body()

    def attach(self, parent, prefix: str):
        """Attach a copy of this asset under ``parent`` (an MjsBody or MjsFrame); names get ``prefix``."""
        import mujoco

        frame = parent.add_frame() if isinstance(parent, mujoco.MjsBody) else parent
        # Attach a fresh copy: MuJoCo attaches by reference, and this spec must stay reusable
        # (attached many times, compiled on its own). Keep the copy alive as long as the asset.
        copy = self.spec.copy()
        self._keep.append(copy)
        return frame.attach_body(copy.worldbody.first_body(), prefix, "")

    def joint(self, name: str) -> AssetJoint:
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(name)
