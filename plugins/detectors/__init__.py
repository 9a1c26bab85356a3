"""Built-in detectors: one module per method."""
