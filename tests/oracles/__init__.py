"""Straightforward reference implementations kept as test oracles for the fast maps."""
