"""``python -m skyradar`` runs the command-line interface."""

from skyradar.cli import main

main()
