"""Procedural generators, one function per vocabulary name, registered with ``core.register``."""
