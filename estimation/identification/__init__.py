"""Identification: the output-error problem, its residual and unknowns, `identify`, and its result."""
