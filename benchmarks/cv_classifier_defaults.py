"""Check ab-hist's defaults without test data: 5-fold stratified CV on the MIT *train* split.

Crosses four lens-search scores (regions.lit_map variants) with Eq. 3.19 mode, min_chroma and
histogram smoothing, and prints the cross-validated accuracy of each setting.

    python benchmarks/cv_classifier_defaults.py
"""
import itertools, sys, cv2, numpy as np, tsrkit
from sklearn.model_selection import StratifiedKFold
from tsrkit.datasets import open_dataset
from tsrkit.types import Candidate, Dataset
import tsrkit_plugins.classifiers.regions as regions
cv2.setNumThreads(1)
train = open_dataset("udacity_mit_tl_crops").split("train")
samples = list(train); labels = [s.annotations[0].state for s in samples]
frames = {s.source: s.load() for s in samples}
orig = regions.lit_map
def v2(bgr):
    v = cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV)[..., 2].astype(np.float32) / 255; return v * v
def sv2_noblue(bgr):
    hsv = cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV); m = orig(bgr)
    blue = (hsv[..., 0] >= 85) & (hsv[..., 0] <= 135)
    return np.where(blue, 0, m)
def v2_noblue(bgr):
    hsv = cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV); v = hsv[..., 2].astype(np.float32) / 255
    blue = (hsv[..., 0] >= 85) & (hsv[..., 0] <= 135) & (hsv[..., 1] > 40)
    return np.where(blue, 0, v * v)
variants = {"sv2": orig, "v2": v2, "sv2_noblue": sv2_noblue, "v2_noblue": v2_noblue}
folds = list(StratifiedKFold(5, shuffle=True, random_state=0).split(samples, labels))
grid = [dict(mode=m, min_chroma=c, smooth=s) for m, c, s in itertools.product(["saturation", "max"], [0.0, 10.0], [0.0, 3.0])]
for vname, fn in variants.items():
    regions.lit_map = fn
    for g in grid:
        correct = 0
        for tr, te in folds:
            cls = tsrkit.classifier("ab-hist", **g)
            model = cls.fit(Dataset("f", tuple(samples[i] for i in tr)))
            cls._model = model
            for i in te:
                s = samples[i]; f = frames[s.source]
                d = cls.classify(f, [Candidate.from_box(s.annotations[0].bbox, 1.0)])[0]
                correct += d.state == labels[i]
        print(f"{vname:11s} {g} cv_acc={correct/len(samples):.4f}", flush=True)
