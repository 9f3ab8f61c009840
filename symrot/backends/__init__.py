"""Backends: modules that print evaluation plans or derivations through templates."""
