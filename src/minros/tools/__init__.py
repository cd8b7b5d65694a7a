"""Library code shared by the command-line tools (rostopic, rosnode, rosparam, rosservice,
rqt_graph): master queries with bounded timeouts, YAML argument filling, message printing."""
