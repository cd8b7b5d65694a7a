"""rviz: minros provides rviz's service definitions (rviz.srv); the visualizer itself and its
Python bindings are not part of minros."""
