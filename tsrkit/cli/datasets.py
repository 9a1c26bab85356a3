"""``tsrkit datasets``."""
COMMANDS = []
