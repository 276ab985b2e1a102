"""GPS legs: classic per-point solutions, legs found in a flight, one global fit over every leg, and their report."""
