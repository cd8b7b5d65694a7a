"""image_transport's republish program."""
