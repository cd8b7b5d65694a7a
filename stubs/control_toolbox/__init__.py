"""control_toolbox: message package stand-in provided by minros."""
