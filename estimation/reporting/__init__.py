"""Reporting a result: its view (summary, JSON, figure), the calibration report, compliance, budget tables,
autopilot parameter files."""
