"""Command-line interface: ``cosim pour | validate | bench | stress | replay | view``."""
