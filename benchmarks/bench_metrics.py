"""Wall time of the other diversity metrics on the 392 baseline texts (prints one JSON object)."""

import json
import time

import numpy as np

from anomalygen.evaluate.baselines import BASELINES, baseline_texts
from anomalygen.evaluate.text_metrics import mean_wmd, sbert_similarity

texts = [t for stem in BASELINES for t in baseline_texts(stem)]
t0 = time.perf_counter()
sbert_similarity(texts[:2])  # load the model outside the timing
load_s = time.perf_counter() - t0
t0 = time.perf_counter()
sim = sbert_similarity(texts)
sbert_s = time.perf_counter() - t0
t0 = time.perf_counter()
wmd = mean_wmd(texts, rng=np.random.default_rng(0), max_pairs=300)
wmd_s = time.perf_counter() - t0
print(json.dumps({"name": "text_metrics_392", "texts": len(texts), "sbert_load_s": round(load_s, 2),
                  "sbert_s": round(sbert_s, 2), "sbert_similarity": round(sim, 4),
                  "wmd_300_pairs_s": round(wmd_s, 2), "wmd": round(wmd, 4)}))
