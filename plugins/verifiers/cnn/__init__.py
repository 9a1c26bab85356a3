"""``cnn-verifier``: a small convolutional network that confirms, boxes and reads every candidate.

Crops around each candidate (:mod:`.windows`) go through an ONNX model in one batch
(:mod:`.runtime`); the network was trained here with PyTorch (:mod:`.training`, the ``train``
extra) on crops of every camera tsrkit has, under camera augmentation (:mod:`.augment`).
"""
