"""The `jets` study: real jet test points through Mach 1 by output error and the self-survey."""
