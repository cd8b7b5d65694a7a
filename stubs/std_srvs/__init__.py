"""std_srvs: message package stand-in provided by minros."""
