"""SBERT, WMD and image similarity behave as distances/similarities should."""

import numpy as np
import pytest

from anomalygen.evaluate import run_metrics as rm
from anomalygen.evaluate.image_metrics import embed_images, image_similarity
from anomalygen.evaluate.text_metrics import (
    _word_piece_bags,
    mean_wmd,
    sbert_similarity,
    word_movers_distance,
)


def test_wmd_zero_for_identical_and_ordered_by_meaning():
    bags, vecs = _word_piece_bags(["a knife on the counter", "a knife on the counter", "a knife on the table",
                                   "purple elephants sing opera"])
    assert word_movers_distance(bags[0], bags[1], vecs) == pytest.approx(0.0, abs=1e-6)
    near, far = word_movers_distance(bags[0], bags[2], vecs), word_movers_distance(bags[0], bags[3], vecs)
    assert 0 < near < far


def test_mean_wmd_is_seeded():
    texts = [f"task number {i} about a {w}" for i, w in enumerate(["knife", "pill", "fridge", "stove", "towel", "bleach"])]
    a = mean_wmd(texts, rng=np.random.default_rng(1), max_pairs=5)
    assert a == mean_wmd(texts, rng=np.random.default_rng(1), max_pairs=5) and a > 0


def test_sbert_similar_texts_score_higher():
    assert sbert_similarity(["a knife on the counter"] * 2) == pytest.approx(1.0, abs=1e-5)
    assert sbert_similarity(["a knife on the counter", "a sharp knife at the counter edge"]) > \
        sbert_similarity(["a knife on the counter", "the cat sleeps in the garden"])


def test_image_similarity_efficientnet(synthetic_run):
    renders = rm.scene_renders(synthetic_run)
    vecs = embed_images(renders)
    assert vecs.shape == (5, 1280) and np.allclose(np.linalg.norm(vecs, axis=1), 1, atol=1e-5)
    sim = image_similarity(renders)
    assert 0 < sim < 1
    assert image_similarity([renders[0], renders[0]]) == pytest.approx(1.0, abs=1e-5)


def test_image_similarity_with_user_torchscript(synthetic_run, tmp_path):
    import torch

    class Tiny(torch.nn.Module):
        def __init__(self):
            super().__init__()
            torch.manual_seed(0)
            self.conv = torch.nn.Conv2d(3, 8, 5, stride=4)

        def forward(self, x):
            return self.conv(x)  # (N, 8, H, W): mean-pooled by the loader

    path = tmp_path / "tiny.pt"
    torch.jit.save(torch.jit.trace(Tiny(), torch.zeros(1, 3, 224, 224)), str(path))
    renders = rm.scene_renders(synthetic_run)
    vecs = embed_images(renders, vit_weights=str(path))
    assert vecs.shape == (5, 8)
    assert -1 <= image_similarity(renders, vit_weights=str(path)) <= 1


def test_bad_user_weights_are_a_user_error(synthetic_run, tmp_path):
    from anomalygen.errors import UserError

    bad = tmp_path / "weights.bin"
    bad.write_bytes(b"not a model")
    with pytest.raises(UserError, match="TorchScript"):
        embed_images(rm.scene_renders(synthetic_run), vit_weights=str(bad))
