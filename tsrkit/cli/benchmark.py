"""``tsrkit benchmark`` and ``compare``."""
COMMANDS = []
