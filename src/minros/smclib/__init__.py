"""smclib: the Python runtime of the State Machine Compiler (SMC), which ROS's bond and
other SMC-generated state machines import as ``smclib.statemap``."""
