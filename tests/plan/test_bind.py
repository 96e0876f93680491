"""The robot's own choice of container: one that ends the hazard once shut, not merely the nearest."""

from __future__ import annotations

from tests.knowledge.graphs import furniture, graph, joint, obj

from anomalygen.knowledge import load_kb
from anomalygen.plan.bind import choose_container, ends_hazard
from anomalygen.schema import LATCHING_PROPERTY


def _scene():
    marble = obj("marble_0", "marble", at="floor", xy=(0.0, 0.0), size=(0.02, 0.02, 0.02))
    carton = furniture("box_0", "Box", xy=(0.3, 0.0), size=(0.5, 0.5, 0.3), joints=[joint("flap", 0.0)])
    cabinet = furniture("storagefurniture_0", "StorageFurniture", xy=(1.5, 0.0), joints=[joint("drawer", 0.0)])
    trash = furniture("trashcan_0", "TrashCan", xy=(0.4, 0.4), size=(0.3, 0.3, 0.4), joints=[joint("lid", 0.0)])
    paper = obj("paper_ball_0", "paper_ball", at="floor", xy=(0.2, 0.3), size=(0.08, 0.08, 0.08))
    safe = furniture("safe_0", "Safe", xy=(2.5, 0.0), size=(0.5, 0.4, 0.5), joints=[joint("door", 0.0)])
    return graph(marble, carton, cabinet, trash, paper, safe)


def test_a_choking_hazard_goes_where_a_latch_keeps_a_toddler_out_not_into_a_nearer_box_or_low_drawer():
    kb, g = load_kb(), _scene()
    hc = kb.hazard_classes["remove_choking_hazards"]
    marble = next(o for o in g.objects if o.name == "marble_0")
    by = {o.name: o for o in g.objects}
    assert not ends_hazard([hc], marble, by["box_0"], g)  # flaps do not keep a toddler out
    assert not ends_hazard([hc], marble, by["storagefurniture_0"], g)  # nor does a low drawer a toddler opens
    assert ends_hazard([hc], marble, by["safe_0"], g)  # a shut safe latches
    g = g.model_copy(update={"objects": [o for o in g.objects if o.name != "safe_0"]})
    assert choose_container(hc, marble, g, kb) == "box_0"  # nothing ends it: the nearest that takes it


def test_shut_flaps_count_as_a_shut_lid_a_latching_box_keeps_a_choking_hazard_out_of_reach_by_either():
    """Flaps enclose as a lid does (the part-label table): a box that latches keeps a toddler out once
    either is shut, and not when it has nothing that shuts."""
    kb, g = load_kb(), _scene()
    hc = kb.hazard_classes["remove_choking_hazards"]
    marble = next(o for o in g.objects if o.name == "marble_0")
    carton = next(o for o in g.objects if o.name == "box_0")
    latching = carton.model_copy(update={"properties": [*carton.properties, LATCHING_PROPERTY]})
    flapped = latching.model_copy(update={"joints": [joint("flap", 0.0)]})
    lidded = latching.model_copy(update={"joints": [joint("lid", 0.0)]})
    open_top = latching.model_copy(update={"joints": []})
    assert ends_hazard([hc], marble, flapped, g) and ends_hazard([hc], marble, lidded, g)
    assert not ends_hazard([hc], marble, open_top, g)
    g = g.model_copy(update={"objects": [flapped if o is carton else o for o in g.objects]})
    assert choose_container(hc, marble, g, kb) == "box_0"  # the nearest container that ends it


def test_litter_is_done_with_once_in_the_nearest_bin():
    kb, g = load_kb(), _scene()
    hc = kb.hazard_classes["pick_up_floor_litter"]
    paper = next(o for o in g.objects if o.name == "paper_ball_0")
    assert ends_hazard([hc], paper, next(o for o in g.objects if o.name == "trashcan_0"), g)
    assert choose_container(hc, paper, g, kb) == "trashcan_0"


def test_stored_shears_go_where_no_other_class_fires_on_them():
    """Inside an open carton or a low cupboard, shears are stored (store_sharp_objects ends) yet within a
    child's reach; shut in a safe they are neither."""
    kb, g = load_kb(), _scene()
    shears = obj("scissors_0", "Scissors", at="table", xy=(0.1, -0.2), size=(0.18, 0.06, 0.02))
    g = g.model_copy(update={"objects": [*g.objects, shears]})
    by = {o.name: o for o in g.objects}
    store = kb.hazard_classes["store_sharp_objects"]
    assert {"Box", "StorageFurniture"} <= set(kb.containers_for(store, "Scissors"))
    # the class's own containers (boxes, cabinets) all leave them within a child's reach, so the child's
    # class's latching kind joins them (KnowledgeBase.containers_for) and the safe is chosen
    assert kb.containers_for(store, "Scissors")[-1] == "Safe"
    assert choose_container(store, shears, g, kb) == "safe_0"
    assert not ends_hazard(list(kb.hazard_classes.values()), shears, by["box_0"], g)
    assert not ends_hazard(list(kb.hazard_classes.values()), shears, by["storagefurniture_0"], g)
    assert ends_hazard(list(kb.hazard_classes.values()), shears, by["safe_0"], g)


def test_a_flat_bag_wider_than_a_bin_has_no_container_however_tall_the_bin():
    """The suction cup lowers litter lying as it lay: a 0.31 m bag does not pass a 0.24 m bin's mouth
    even though the bin is taller than the bag is wide; a bin wide enough takes it."""
    from anomalygen.errors import ItemFailed

    kb = load_kb()
    hc = kb.hazard_classes["pick_up_floor_litter"]
    bag = obj("plastic_bag_0", "plastic_bag", at="floor", xy=(0.0, 0.0), size=(0.31, 0.30, 0.012))
    narrow = furniture("trashcan_0", "TrashCan", xy=(0.4, 0.0), size=(0.24, 0.23, 0.34), joints=[joint("lid", 0.0)])
    g = graph(bag, narrow)
    try:
        choose_container(hc, bag, g, kb)
        raise AssertionError("a bag wider than the bin was given the bin")
    except ItemFailed as exc:
        assert "plastic_bag_0" in str(exc) and "TrashCan" in str(exc)
    wide = furniture("trashcan_1", "TrashCan", xy=(1.0, 0.0), size=(0.55, 0.54, 0.65), joints=[joint("lid", 0.0)])
    assert choose_container(hc, bag, graph(bag, narrow, wide), kb) == "trashcan_1"


def test_a_bin_under_a_wall_shelf_gives_way_to_a_free_bin_its_lid_can_open_under():
    """The seed-0 loop's t0048 at 4726c82: the nearer of two bins stood under a wall shelf, its lid
    stopped half open against the shelf, and the spoiled carton landed on the lid. A bin with nothing
    over it is chosen first; with only covered bins, the nearest still is."""
    from anomalygen.schema import Relation

    kb = load_kb()
    hc = kb.hazard_classes["pick_up_floor_litter"]
    paper = obj("paper_ball_0", "paper_ball", at="floor", xy=(0.0, 0.0), size=(0.08, 0.08, 0.08))
    near = furniture("trashcan_1", "TrashCan", xy=(0.3, 0.0), size=(0.45, 0.45, 0.7), joints=[joint("lid", 0.0)])
    far = furniture("trashcan_0", "TrashCan", xy=(1.2, 0.0), size=(0.6, 0.6, 0.7), joints=[joint("lid", 0.0)])
    shelf = furniture("shelf_0", "shelf", xy=(0.3, 0.0), size=(0.36, 0.7, 0.28))
    under = [Relation(subject="trashcan_1", predicate="under", object="shelf_0")]
    assert choose_container(hc, paper, graph(paper, near, far, shelf, relations=under), kb) == "trashcan_0"
    assert choose_container(hc, paper, graph(paper, near, far, shelf), kb) == "trashcan_1"
    assert choose_container(hc, paper, graph(paper, near, shelf, relations=under), kb) == "trashcan_1"
