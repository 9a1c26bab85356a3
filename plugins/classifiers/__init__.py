"""Built-in state and sign classifiers: one module per method."""
