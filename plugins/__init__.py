"""tsrkit's built-in plugins, each registered through the ``tsrkit`` entry-point group."""
