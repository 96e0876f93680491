"""Knowledge-base consistency: every reference resolves, every vocabulary name is described."""

from __future__ import annotations

from anomalygen.knowledge import PROPERTIES, load_kb
from anomalygen.knowledge.base import vocabulary
from anomalygen.schema import HazardCategory

PAPER_CLASSES = {
    "store_sharp_objects", "reduce_tripping_hazards", "manage_chemical_risks", "dispose_spoiled_food",
    "close_open_refrigerator", "pick_up_floor_litter", "ventilate_room", "keep_sharp_away_from_children",
    "remove_choking_hazards", "close_open_furniture", "secure_medications",
}


def test_knowledge_base_is_consistent():
    assert load_kb().problems() == []


def test_paper_classes_present_with_categories():
    kb = load_kb()
    assert {hc.id for hc in kb.paper_classes()} == PAPER_CLASSES
    assert kb.hazard_classes["ventilate_room"].category == HazardCategory.HYGIENE
    assert kb.hazard_classes["secure_medications"].category == HazardCategory.CHILD_SAFETY
    assert len(kb.hazard_classes) >= 20
    for cat in HazardCategory:
        assert kb.classes_in(cat)


def test_every_vocabulary_name_has_object_info():
    kb, voc = load_kb(), vocabulary()
    assert set(voc["targets"]) | set(voc["household"]) <= set(kb.objects)
    assert len(kb.targets) == 44
    for o in kb.objects.values():
        assert set(o.properties) <= set(PROPERTIES)


def test_small_parts_rule():
    """choking_size objects are small enough for the 57.1 mm cylinder (uninflated balloons excepted:
    they compress), and obviously large objects are not marked."""
    kb = load_kb()
    for o in kb.objects.values():
        if "choking_size" in o.properties and "soft" not in o.properties:
            assert o.size_range[1] <= 0.0571, o.name
    for name in ("pill", "marble", "coin", "button_battery", "lego_brick", "USB"):
        assert "choking_size" in kb.objects[name].properties
    for name in ("ball", "Lighter", "apple", "Phone"):
        assert "choking_size" not in kb.objects[name].properties


def test_articulated_classes_reference_real_parts():
    kb = load_kb()
    for hc in kb.hazard_classes.values():
        if hc.articulation is None:
            continue
        # the articulated object is the hazard (an open fridge) or the target it is in (a microwave with a fork inside)
        var = hc.articulation.variable
        if var == hc.hazard_variable:
            names = kb.hazard_candidates(hc)
        elif var == "$target":
            names = hc.target_assets
        else:  # a composed class's other object: the lit burner a towel lies on
            names = kb.static_candidates(hc, var)
        for name in names:
            part = kb.articulation_part(hc, name)
            assert part is not None and part in {p.label for p in kb.objects[name].parts}, (hc.id, name)


def test_roles_and_benign_clutter():
    kb = load_kb()
    assert len(kb.roles) == 10
    assert {"homemaker", "engineer", "home_security_officer"} <= set(kb.roles)
    benign = kb.benign_objects()
    assert "cup" in benign and "kitchen_knife" not in benign and "pill" not in benign
