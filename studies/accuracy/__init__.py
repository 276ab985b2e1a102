"""Accuracy studies of the calibration on simulated flights (the paper's figures and more): sample size,
maneuvers, wind, sensitivity, coverage, noise, budget, leak."""
