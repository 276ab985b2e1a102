"""Uncertainty of an identification: the colored-residual covariance, the residual noise model, the GUM budget."""
