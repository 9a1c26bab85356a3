"""Reporting: ``benchmark`` and ``compare`` runs, ``report.json``, run folders and their writers,
track-run reports and drawn overlays."""

__all__: list[str] = []
