"""The `real-alfa` study: the real ALFA Carbon-Z flight."""
