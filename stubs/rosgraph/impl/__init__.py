"""rosgraph.impl: internals of rosgraph (the graph rqt_graph polls)."""
