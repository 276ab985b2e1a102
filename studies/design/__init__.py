"""The `design` study: the information-optimal schedule against the paper's profiles."""
