"""The rooms of the core, lowest first: a module imports only from its own room and the rooms
below it (``tests/core/test_import_graph.py`` checks every import statement against this).

Rooms on one floor (one tuple) stand beside each other and import neither one another nor any
room above. ``""`` is the package itself, ``tsrkit``: the face for library users, beside
``api``, the face for plugin authors, and ``_library``, the Python API calls behind the face.
"""

ROOMS: tuple[tuple[str, ...], ...] = (
    ("core", "_rooms"),  # plain types, records, geometry, metric results, files, atomic writes
    ("plugin",),  # hook specs, parameters, base classes, registry, selection, presets, models
    ("datasets", "eval"),  # dataset reading and registry; metrics and their settings
    ("runner",),  # frames, engine, workers, streams, follow, agreement, training
    ("geo",),  # GPS tracks, maps, vicinity (research)
    ("sun", "spatiotemporal"),  # Sun geometry; Zheng's spatiotemporal framework (research)
    ("synth",),  # synthetic scenes, drives, video (research)
    ("reporting",),  # benchmark, compare, report.json, run folders, track reports, drawing
    ("", "api", "_library"),  # the faces: tsrkit for library users, tsrkit.api for plugins
    ("cli",),  # the command line, a thin layer over the faces
    ("__main__",),  # python -m tsrkit
)
