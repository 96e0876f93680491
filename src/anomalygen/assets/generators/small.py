"""Target-category generators."""
