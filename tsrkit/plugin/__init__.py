"""The plugin system: hook specifications, parameter schemas, plugin base classes, the registry,
selection from text (``--param``, YAML, presets), model files and the one-frame pipeline."""

__all__: list[str] = []
