"""Retrieval text for an asset: what it is, how big, what moves, and why it can be dangerous.

Sentence-BERT retrieval only finds what the text says, so descriptions spell out the facts queries
ask about ("small enough to choke on", "sharp blade", "hot surface") rather than just a name.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from anomalygen.assets.names import object_table, vocabulary

if TYPE_CHECKING:
    from anomalygen.assets.model import Asset

_TAG_TEXT = {
    "choking_size": "small enough for a toddler to put in the mouth and choke on",
    "small_parts": "has small parts a young child could swallow",
    "medication": "medicine that is poisonous if a child swallows it",
    "toxic": "toxic if swallowed",
    "chemical": "household chemical, poisonous",
    "corrosive": "corrosive, burns skin",
    "sharp": "sharp edge or blade that can cut",
    "pointed": "pointed tips that can poke or stab",
    "fragile": "fragile, breaks into sharp pieces if dropped",
    "hot": "can be hot and cause burns",
    "fire": "fire and burn risk",
    "heavy": "heavy, can hurt if it falls",
    "trip": "trip hazard when left on the floor",
    "slip": "slip hazard on the floor",
    "electrical": "electrical appliance with a cable",
    "suffocation": "suffocation risk for small children",
    "strangulation": "long cord, strangulation risk for children",
    "food": "food",
    "spoiled": "spoiled, unhygienic, should be thrown away",
    "perishable": "perishable, must be kept refrigerated",
    "litter": "litter that belongs in the trash",
    "toy": "child's toy",
    "tip_over": "can tip over if climbed or pulled",
    "large_furniture": "large piece of furniture or appliance with doors",
    "pinch": "can pinch fingers",
    "moving_blades": "moving blades",
    "drowning_risk": "can hold water, drowning risk for small children",
    "climbable": "children can climb on it",
    "lockable": "lockable storage for dangerous items",
    "lidded": "has a lid, safe storage container",
    "hygiene": "hygiene-related",
    "contains_battery": "contains button or AA batteries",
    "entrapment": "a child could get trapped inside",
    "fall_risk": "fall risk for children when open",
    "wheeled": "rolls on wheels",
}


TARGET_BLURBS = {
    "Bottle": "bottle with a cap",
    "Box": "storage box",
    "Bucket": "open bucket with a handle",
    "Camera": "photo camera",
    "Cart": "wheeled trolley cart with shelves",
    "Chair": "chair",
    "Clock": "desk clock",
    "CoffeeMachine": "coffee machine",
    "Dishwasher": "kitchen dishwasher",
    "Dispenser": "soap or lotion pump dispenser",
    "Display": "computer monitor screen",
    "Door": "room door",
    "Eyeglasses": "pair of glasses",
    "Fan": "electric fan",
    "FoldingChair": "folding chair",
    "Globe": "desk globe",
    "Kettle": "electric kettle",
    "Keyboard": "computer keyboard",
    "KitchenPot": "cooking pot with a lid",
    "Knife": "folding pocket knife",
    "Lamp": "desk lamp",
    "Laptop": "laptop computer",
    "Microwave": "microwave oven",
    "Mouse": "computer mouse",
    "Oven": "kitchen oven and stove",
    "Pen": "pen",
    "Phone": "mobile phone",
    "Pliers": "pliers",
    "Printer": "printer",
    "Refrigerator": "fridge / refrigerator",
    "Remote": "TV remote control",
    "Safe": "safe",
    "Scissors": "scissors",
    "Stapler": "stapler",
    "StorageFurniture": "cabinet / storage furniture",
    "Suitcase": "suitcase",
    "Table": "table",
    "Toaster": "toaster",
    "Toilet": "toilet",
    "TrashCan": "trash can / rubbish bin",
    "USB": "USB stick",
    "WashingMachine": "washing machine",
    "Window": "window",
    "Lighter": "cigarette lighter",
}


def size_words(size: float) -> str:
    if size < 0.03:
        return "tiny"
    if size < 0.1:
        return "small"
    if size < 0.4:
        return "hand-sized" if size < 0.25 else "medium-sized"
    if size < 1.0:
        return "large"
    return "very large"


def base_text(name: str) -> str:
    """What every variant of a name shares: what it is and its hazards (from the tag table)."""
    _, _, group, tag_list = object_table()[name]
    blurb = vocabulary()["household"].get(name) or TARGET_BLURBS.get(name) or f"{name} ({group})"
    parts = [f"{name.replace('_', ' ')}: {blurb}"]
    parts += [_TAG_TEXT[t] for t in sorted(set(tag_list)) if t in _TAG_TEXT and t != "food"]
    return "; ".join(parts)


def variant_text(name: str, asset: Asset, features: list[str], *, dims: bool = True) -> str:
    """What this variant adds: size, mass, look, moving parts, size-derived hazards. Short, so a
    catalogue of thousands embeds quickly (see ``retrieval.embeddings``)."""
    tag_list = object_table()[name][3]
    size = asset.size
    ext = asset.aabb[1] - asset.aabb[0]
    d = ".1f" if size < 0.1 else ".0f"
    mass = f"{asset.mass * 1000:.0f} g" if asset.mass < 0.5 else f"{asset.mass:.1f} kg"
    head = f"{size_words(size)} {name.replace('_', ' ')}, about {size * 100:{d}} cm across"
    if dims:
        head += f" ({ext[0] * 100:{d}} x {ext[1] * 100:{d}} x {ext[2] * 100:{d}} cm), {mass}"
    parts = [head]
    if features:
        parts.append(", ".join(features))
    labels = sorted({j.label for j in asset.joints})
    if labels:
        parts.append("movable parts: " + ", ".join(labels))
    if asset.cavities:
        parts.append("can hold things inside")
    if asset.surfaces:
        parts.append("has surfaces to put things on")
    if size < 0.045 and "choking_size" not in tag_list:
        parts.append(_TAG_TEXT["choking_size"])
    if size >= 0.06 and "choking_size" not in tag_list:
        parts.append("too big to swallow")
    return "; ".join(parts)


def describe(name: str, asset: Asset, features: list[str]) -> str:
    """The full retrieval/display text: the variant's facts, then what the name always implies."""
    return f"{variant_text(name, asset, features)}; {base_text(name)}"


def properties(name: str, size: float) -> list[str]:
    """Property tags for the catalogue (the same words the knowledge base uses where they overlap)."""
    t = set(object_table()[name][3])
    if size < 0.045:
        t.add("choking_size")
    return sorted(t)
