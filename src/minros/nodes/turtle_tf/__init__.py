"""The turtlesim tf tutorial of geometry_tutorials (package ``turtle_tf``): a broadcaster per
turtle pose, and a listener that makes turtle2 follow turtle1."""
