"""ar_track_alvar_msgs: message package stand-in provided by minros."""
