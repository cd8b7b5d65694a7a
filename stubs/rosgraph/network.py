"""rosgraph.network: addresses a node binds to and advertises, and the TCPROS connection
header codec (minros.rosenv, minros.wire.tcpros, minros.wire.sockets)."""

from minros.rosenv import (  # noqa: F401
    create_local_xmlrpc_uri,
    get_address_override,
    get_bind_address,
    get_host_name,
    get_local_address,
    get_local_addresses,
    is_local_address,
    parse_http_host_and_port,
    use_ipv6,
)
from minros.wire.tcpros import HeaderError as ROSHandshakeException  # noqa: F401, E402
from minros.wire.tcpros import encode_header


def encode_ros_handshake_header(header: dict) -> bytes:
    """A connection header, length prefix included; keys and values may be str or UTF-8
    bytes, as rosgraph accepts them."""
    def text(x):  # noqa: ANN001, ANN202
        return x.decode("utf-8") if isinstance(x, bytes) else x
    return encode_header({text(k): text(v) for k, v in header.items()})


def decode_ros_handshake_header(header_str: bytes) -> dict:
    """The fields of a connection header given with its length prefix (extra bytes ignored);
    keys lose surrounding blanks, as rosgraph strips them."""
    from minros.wire.tcpros import read_header_block

    found = read_header_block(header_str)
    if found is None:
        raise ROSHandshakeException(f"Incomplete header: only {len(header_str)} bytes")
    return {key.strip(): value for key, value in found[0].items()}


def read_ros_handshake_header(sock, b=None, buff_size: int = 65536) -> dict:  # noqa: ANN001
    """Read one connection header from ``sock``."""
    from minros.wire.sockets import read_header

    return read_header(sock)


def write_ros_handshake_header(sock, header: dict) -> int:  # noqa: ANN001
    """Send ``header`` on ``sock``; returns the bytes sent."""
    data = encode_ros_handshake_header(header)
    sock.sendall(data)
    return len(data)


ROS_HOSTNAME = "ROS_HOSTNAME"
ROS_IP = "ROS_IP"
ROS_IPV6 = "ROS_IPV6"
SIOCGIFADDR = 35093
SIOCGIFCONF = 35090
python3 = 1
