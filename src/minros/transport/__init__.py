"""Transports: how the bytes of a topic connection move, behind one interface.

``base`` is the seam (``Transport``: negotiate, send a frame, receive frames, close;
``ProtocolHandler``: a protocol a node speaks); ``streams`` the byte stream a TCPROS transport
runs over (a socket, or an in-memory stream in tests); ``tcpros_base`` the connection-header
exchange on a stream; ``tcpros_pubsub`` TCPROS for topics, the first implementation.
"""
