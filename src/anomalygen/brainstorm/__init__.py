"""brainstorm stage."""
