"""Self-BLEU speed-up over the NLTK reference on 1,000 texts (prints one JSON object).

The texts are the six packaged baselines' task texts, cycled with a numbered suffix to reach 1,000.
NLTK on all 1,000 texts takes minutes, so it is timed on a seeded subsample of texts (each still
scored against all 999 others) and extrapolated linearly — each text's score costs the same work.
Exactness is checked on that subsample.
"""

import json
import sys
import time

import numpy as np

from anomalygen.evaluate.baselines import BASELINES, baseline_texts
from anomalygen.evaluate.selfbleu import self_bleu_reference_scores, self_bleu_scores

N, SUBSAMPLE = 1000, int(sys.argv[1]) if len(sys.argv) > 1 else 50

pool = [t for stem in BASELINES for t in baseline_texts(stem)]
texts = [f"{pool[i % len(pool)]} variant {i // len(pool)}" for i in range(N)]

t0 = time.perf_counter()
fast = self_bleu_scores(texts)
fast_s = time.perf_counter() - t0

idx = sorted(np.random.default_rng(0).choice(N, size=SUBSAMPLE, replace=False).tolist())
t0 = time.perf_counter()
ref = self_bleu_reference_scores(texts, idx)
ref_sub_s = time.perf_counter() - t0
ref_s = ref_sub_s * N / SUBSAMPLE

print(json.dumps({
    "name": "selfbleu_1000",
    "texts": N,
    "fast_s": round(fast_s, 4),
    "nltk_s_extrapolated": round(ref_s, 2),
    "nltk_subsample": SUBSAMPLE,
    "speedup": round(ref_s / fast_s, 1),
    "max_abs_diff": max(abs(fast[i] - r) for i, r in zip(idx, ref, strict=False)),
}))
