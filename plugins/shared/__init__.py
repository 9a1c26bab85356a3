"""Helpers that several kinds of built-in plugin share (detectors, verifiers, classifiers,
formats, writers): each kind may import from here, and from no other kind's folder."""
