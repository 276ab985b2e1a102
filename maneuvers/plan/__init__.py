"""Planning a calibration maneuver: speed profiles, the lateral-path OCP, optimal designs, the pilot card,
the auto-throttle, missions and the plan's output files."""
