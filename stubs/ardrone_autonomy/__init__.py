"""ardrone_autonomy: minros provides the driver's message and service definitions only."""
