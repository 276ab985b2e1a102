"""Flying a plan in simulation: the simulator and its options, guidance, sensors, turbulence, faults, truth,
the JSBSim engine and simulated leg flights."""
