"""PartNet-Mobility and Objaverse importers on fixtures written in the exact on-disk formats."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import mujoco
import pytest

from anomalygen.assets.importers import load_objaverse, load_partnet, prepare_urdf, read_semantics
from anomalygen.assets.validate import validate_asset
from anomalygen.errors import UserError
from anomalygen.schema import AssetSource

from .fixtures import write_box_obj, write_objaverse_item, write_partnet_cabinet


def test_prepare_urdf_strips_package_paths_and_keeps_visuals(tmp_path):
    folder = write_partnet_cabinet(tmp_path / "45135")
    xml = prepare_urdf((folder / "mobility.urdf").read_text(), folder / "textured_objs")
    root = ET.fromstring(xml)
    assert all(not m.get("filename").startswith("package://") for m in root.iter("mesh"))
    comp = root.find("mujoco/compiler")
    assert comp.get("discardvisual") == "false" and comp.get("strippath") == "true"


def test_partnet_folder_becomes_an_articulated_asset(tmp_path):
    folder = write_partnet_cabinet(tmp_path / "45135")
    assert read_semantics(folder / "semantics.txt")["link_1"] == ("hinge", "door")
    a = load_partnet(folder, size=0.9)
    assert (
        a.source == AssetSource.PARTNET and a.category == "StorageFurniture" and a.asset_id == "partnet:45135"
    )
    labels = {j.name: j for j in a.joints}
    assert labels["joint_1"].label == "door" and labels["joint_1"].type == "hinge"
    assert labels["joint_1"].range == pytest.approx((0.0, 1.57))
    assert labels["joint_2"].label == "drawer" and labels["joint_2"].type == "slide"
    assert labels["joint_2"].range[1] == pytest.approx(0.2 * a.params["scale"])  # slides scale with the model
    assert a.size == pytest.approx(0.9)
    # Y-up model rotated to Z-up: the 0.8 m tall body (y in the file) is now the height
    ext = a.aabb[1] - a.aabb[0]
    assert ext[2] == pytest.approx(max(ext))
    model = a.spec.copy().compile()
    assert [b for b in a.spec.worldbody.bodies][0].name == "root"
    assert model.ngeom >= 3 and model.nmesh == 3
    result = validate_asset(a, render=False)
    assert result.ok, result.reason
    assert a.ref.source == AssetSource.PARTNET and a.ref.path == str(folder)


def test_partnet_missing_urdf_is_a_user_error(tmp_path):
    with pytest.raises(UserError, match="mobility.urdf"):
        load_partnet(tmp_path)


def test_objaverse_obj_with_annotations_becomes_a_rigid_asset(tmp_path):
    obj, _ = write_objaverse_item(tmp_path, uid="8f2a9c", name="mug")
    a = load_objaverse(obj)
    assert a.source == AssetSource.OBJAVERSE and a.asset_id == "objaverse:8f2a9c" and a.joints == []
    assert "ceramic" in a.description and "mug" in a.description
    from anomalygen.assets import size_range

    lo, hi = size_range("mug")
    assert lo <= a.size <= hi  # default size from the vocabulary name
    assert a.mass > 0
    assert validate_asset(a, render=False).ok
    b = load_objaverse(obj, size=0.3)
    assert b.size == pytest.approx(0.3)
    m = b.spec.copy().compile()
    assert m.nmesh == 1 and m.geom_type[0] == mujoco.mjtGeom.mjGEOM_MESH


def test_glb_without_trimesh_is_refused_clearly(tmp_path):
    glb = tmp_path / "thing.glb"
    glb.write_bytes(b"glTF\x02\x00\x00\x00")
    try:
        import trimesh  # noqa: F401
    except ImportError:
        with pytest.raises(UserError, match="trimesh"):
            load_objaverse(glb)
    else:  # pragma: no cover - only where trimesh is installed
        pytest.skip("trimesh installed: GLB conversion path is used instead")


def test_obj_box_fixture_is_a_closed_mesh(tmp_path):
    p = write_box_obj(tmp_path / "b.obj", 0.1, 0.2, 0.3)
    lines = p.read_text().splitlines()
    assert sum(ln.startswith("v ") for ln in lines) == 8 and sum(ln.startswith("f ") for ln in lines) == 12
