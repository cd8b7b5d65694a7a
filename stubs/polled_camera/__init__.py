"""polled_camera: minros provides the package's service definition only."""
