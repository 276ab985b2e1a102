"""The studies' engine: one shape of a study, the Monte Carlo runner on Dask, what every run does
(plan, fly, identify, score), and figure helpers."""
