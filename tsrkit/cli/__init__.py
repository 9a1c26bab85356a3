"""The ``tsrkit`` command line: a thin click layer over the Python API."""

__all__: list[str] = []
