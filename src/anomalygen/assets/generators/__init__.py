"""Procedural generators, one function per vocabulary name, registered with ``registry.register``."""
