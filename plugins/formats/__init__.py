"""Built-in dataset formats: one reader (and writer) per annotation format."""
