"""theora_image_transport: minros provides the package's message definition only."""
