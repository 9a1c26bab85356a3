"""Running pipelines: frames from images, folders and videos, the engine (cache, process pools,
Dask), worker processes, streams and ``--follow``, agreement between runs, and training."""

__all__: list[str] = []
