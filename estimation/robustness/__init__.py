"""Robustness checks of an identification: plausibility gates and trimming, jumps, consistency over the flight."""
