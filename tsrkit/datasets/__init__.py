"""Dataset registry, opening datasets by name or path, and the synthetic sample."""
