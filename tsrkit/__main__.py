"""``python -m tsrkit`` runs the command line."""

from tsrkit.cli.main import main

main()
