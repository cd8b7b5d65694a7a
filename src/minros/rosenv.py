"""The ROS environment rules in one place: master URI, ROS_HOME, the log directory, the
addresses a node binds to and advertises (ROS_IP, ROS_HOSTNAME, ROS_IPV6), and the peers its
servers accept (ROS_ALLOWED_HOSTS, minros's own: ROS 1 has no access control).

Every tool and node reads these the same way, as rosgraph.rosenv does: ``__master:=`` beats
``ROS_MASTER_URI`` (default ``http://localhost:11311/``); ``ROS_HOME`` defaults to ``~/.ros``;
``ROS_LOG_DIR`` defaults to ``$ROS_HOME/log``, where each roscore/roslaunch run has a
directory named by its run_id and ``latest`` links to the newest one.
"""

from __future__ import annotations

import functools
import ipaddress
import os
import re
import socket
import sys
from pathlib import Path
from typing import Iterable, Mapping, Optional, Sequence, Tuple, Union
from urllib.parse import urlparse

from minros.exceptions import ROSInitException

DEFAULT_MASTER_PORT = 11311
DEFAULT_MASTER_URI = f"http://localhost:{DEFAULT_MASTER_PORT}/"


class MasterURIError(ROSInitException, ValueError):
    """ROS_MASTER_URI (or ``__master:=``) is not a master's URI; the text names the value and
    the fix. A ValueError, as rosgraph raises for it, and init_node's ROSInitException."""


@functools.lru_cache(maxsize=16)  # read on every master call (lookupService ...): parse once
def _master_uri_problem(uri: str) -> Optional[str]:
    """What is wrong with ``uri`` as a master's URI (rosgraph's test: a scheme and a host, and
    the scheme one XML-RPC speaks), or None."""
    try:
        parsed = urlparse(uri)
        parsed.port  # noqa: B018 - ValueError when the port is not a number in range
    except ValueError:
        return "its port is not a number from 0 to 65535"
    if "://" not in uri:
        return "it lacks the scheme http://"
    if parsed.scheme not in ("http", "https"):
        return f"its scheme is '{parsed.scheme}', where the master speaks http"
    if not parsed.hostname:
        return "it names no host"
    return None


def check_master_uri(uri: str, source: str = "ROS_MASTER_URI") -> str:
    """``uri`` if it is a master's URI, else MasterURIError naming ``source`` (the variable or
    the ``__master:=`` argument it came from) and the fix."""
    problem = _master_uri_problem(uri)
    if problem is None:
        return uri
    fix = None
    if "://" not in uri:
        fix = "http://" + uri
    elif urlparse(uri).scheme not in ("http", "https"):
        fix = "http://" + uri.split("://", 1)[1]
    if fix is None or _master_uri_problem(fix) is not None:
        fix = f"http://HOST:PORT, as {DEFAULT_MASTER_URI.rstrip('/')}"
    if source == "__master":
        raise MasterURIError(f"__master:={uri} is not a master URI ({problem}): use "
                             f"__master:={fix}")
    raise MasterURIError(f"{source} is '{uri}', which is not a master URI ({problem}): "
                         f"set {source}={fix}")


def get_master_uri(env: Optional[Mapping[str, str]] = None,
                   remapped: Optional[str] = None, check: bool = True) -> str:
    """The master's URI: a ``__master:=`` value (``remapped``), else ROS_MASTER_URI, else default.

    Every reader of the master URI comes here: one that is not a URI (``localhost:11311``) is
    MasterURIError naming it and the fix, unless ``check`` is False (roswtf reports it itself).
    """
    if remapped:
        return check_master_uri(remapped, "__master") if check else remapped
    env = os.environ if env is None else env
    uri = env.get("ROS_MASTER_URI") or DEFAULT_MASTER_URI
    return check_master_uri(uri) if check else uri


def remapped_master(argv: Iterable[str]) -> Optional[str]:
    """The value of the first ``__master:=`` argument (the one rosgraph reads), or None;
    ValueError (rosgraph's text) for one without a value or with a second ``:=``."""
    for arg in argv:
        if arg.startswith("__master:="):
            value = arg[len("__master:="):]
            if not value or ":=" in value:
                raise ValueError(f"__master remapping argument '{arg}' improperly specified")
            return value
    return None


def ros_home(env: Optional[Mapping[str, str]] = None) -> Path:
    """ROS_HOME, else ``~/.ros`` (``~`` from ``env``'s HOME when it has one)."""
    env = os.environ if env is None else env
    if env.get("ROS_HOME"):
        return Path(env["ROS_HOME"])
    return (Path(env["HOME"]) if env.get("HOME") else Path.home()) / ".ros"


def ros_log_dir(env: Optional[Mapping[str, str]] = None) -> Path:
    """ROS_LOG_DIR, else ``$ROS_HOME/log``."""
    env = os.environ if env is None else env
    if env.get("ROS_LOG_DIR"):
        return Path(env["ROS_LOG_DIR"])
    return ros_home(env) / "log"


def test_results_dir(env: Optional[Mapping[str, str]] = None) -> Path:
    """ROS_TEST_RESULTS_DIR, else ``$ROS_HOME/test_results`` (where rostest writes JUnit XML)."""
    env = os.environ if env is None else env
    if env.get("ROS_TEST_RESULTS_DIR"):
        return Path(env["ROS_TEST_RESULTS_DIR"])
    return ros_home(env) / "test_results"


def renew_latest_log_dir(run_dir: Path) -> None:
    """Point ``<log dir>/latest`` at ``run_dir`` (a run's directory), as roscore and roslaunch
    do. A ``latest`` that is a real file or directory is left alone; failures print rosgraph's
    INFO line and never stop the caller (a log link is not worth stopping a launch for)."""
    latest = Path(run_dir).parent / "latest"
    try:
        if latest.is_symlink():
            latest.unlink()
        elif latest.exists():
            sys.stderr.write("INFO: cannot create a symlink to latest log directory\n")
            return
        latest.symlink_to(run_dir)
    except OSError as exc:
        sys.stderr.write(f"INFO: cannot create a symlink to latest log directory: {exc}\n")


# ---------------------------------------------------------------------------------------------
# addresses nodes bind to and advertise (ROS_IP / ROS_HOSTNAME, as rosgraph.network)


def get_address_override(env: Mapping[str, str] | None = None,
                         argv: Sequence[str] | None = None) -> str | None:
    """``__hostname:=``/``__ip:=`` argument, else ROS_HOSTNAME, else ROS_IP, else None."""
    argv = sys.argv if argv is None else argv
    env = os.environ if env is None else env
    for arg in argv:
        if arg.startswith("__hostname:=") or arg.startswith("__ip:="):
            return arg.split(":=", 1)[1]
    if "ROS_HOSTNAME" in env:
        return env["ROS_HOSTNAME"]
    if "ROS_IP" in env:
        return env["ROS_IP"]
    return None


def use_ipv6(env: Mapping[str, str] | None = None) -> bool:
    env = os.environ if env is None else env
    return env.get("ROS_IPV6") == "on"


def get_bind_address(address: str | None = None, env: Mapping[str, str] | None = None) -> str:
    """Loopback when the advertised address is local-only, else the wildcard address."""
    if address is None:
        address = get_address_override(env)
    ipv6 = use_ipv6(env)
    if address and (address == "localhost" or address.startswith("127.") or address == "::1"):
        if ipv6:
            return "::1"
        return address if address.startswith("127.") else "127.0.0.1"
    return "::" if ipv6 else "0.0.0.0"


def get_host_name(env: Mapping[str, str] | None = None) -> str:
    """Host name for advertised URIs: the override, else the host name, else a local address."""
    host = get_address_override(env)
    if host:
        return host
    try:
        host = socket.gethostname()
    except OSError:
        host = ""
    if not host or host == "localhost" or host.startswith("127."):
        host = "::1" if use_ipv6(env) else "127.0.0.1"
    return host


def create_local_xmlrpc_uri(port: int, env: Mapping[str, str] | None = None) -> str:
    return f"http://{get_host_name(env)}:{port}/"


def parse_http_host_and_port(url: str) -> tuple:
    """``(host, port)`` of an ``http://`` URI (port 80 when absent); ``ValueError`` when the
    scheme or host is missing (rosgraph.network's check of a master URI)."""
    from urllib.parse import urlparse

    if not url:
        raise ValueError("not a valid URL")
    parts = urlparse(url)
    if not parts.scheme or not parts.hostname:
        raise ValueError("not a valid URL")
    return parts.hostname, parts.port or 80


def _interface_addresses() -> tuple:
    """(IPv4, IPv6) addresses of this machine's interfaces: ioctl SIOCGIFADDR per interface
    and /proc/net/if_inet6 on Linux, else the addresses the host name resolves to."""
    v4: list = []
    v6: list = []
    try:
        import fcntl
        import struct

        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
            for _index, name in socket.if_nameindex():
                request = struct.pack("256s", name.encode()[:15])
                try:
                    answer = fcntl.ioctl(sock.fileno(), 0x8915, request)  # SIOCGIFADDR
                except OSError:
                    continue  # no IPv4 address on this interface
                v4.append(socket.inet_ntoa(answer[20:24]))
    except (ImportError, OSError, AttributeError):
        v4 = []
    try:
        with open("/proc/net/if_inet6") as f:
            for line in f:
                hexaddr = line.split()[0]
                v6.append(socket.inet_ntop(socket.AF_INET6, bytes.fromhex(hexaddr)))
    except (OSError, ValueError, IndexError):
        pass
    if not v4:
        try:
            v4 = sorted({a[4][0] for a in socket.getaddrinfo(socket.gethostname(), 0,
                                                              socket.AF_INET, 0, socket.SOL_TCP)})
        except OSError:
            v4 = ["127.0.0.1"]
    return v4, v6


def get_local_addresses(env: Mapping[str, str] | None = None) -> list:
    """This machine's addresses (IPv6 first when ROS_IPV6 is on); not affected by ROS_IP."""
    v4, v6 = _interface_addresses()
    return v6 + v4 if use_ipv6(env) else v4


def get_local_address(env: Mapping[str, str] | None = None) -> str:
    """The address override, else the one non-loopback address, else loopback."""
    override = get_address_override(env)
    if override:
        return override
    addrs = get_local_addresses(env)
    if len(addrs) == 1:
        return addrs[0]
    for addr in addrs:
        if not addr.startswith("127.") and addr != "::1":
            return addr
    return "::1" if use_ipv6(env) else "127.0.0.1"


def is_local_address(hostname: str, env: Mapping[str, str] | None = None) -> bool:
    """Whether ``hostname`` resolves to loopback or to one of this machine's addresses."""
    family = 0 if use_ipv6(env) else socket.AF_INET
    try:
        ips = [str(a[4][0]) for a in socket.getaddrinfo(hostname, 0, family, 0, socket.SOL_TCP)]
    except (OSError, UnicodeError):
        return False
    if any(ip.startswith("127.") or ip == "::1" for ip in ips):
        return True
    return bool(set(ips) & ({"localhost"} | set(get_local_addresses(env))))

# ---------------------------------------------------------------------------------------------
# the peers a master's or a node's servers accept (ROS_ALLOWED_HOSTS)

#: the environment variable of the allow-list (the name ROS 2's first localhost-only proposal
#: used; ROS 1 has no access control at all)
ALLOWED_HOSTS_VAR = "ROS_ALLOWED_HOSTS"

Network = Union[ipaddress.IPv4Network, ipaddress.IPv6Network]
_LOOPBACK = (ipaddress.ip_network("127.0.0.0/8"), ipaddress.ip_network("::1/128"))


def parse_allowed_hosts(text: str) -> Tuple[Network, ...]:
    """The networks of an allow-list: entries separated by commas, semicolons or spaces, each
    an address (``10.0.0.5``, ``fe80::1``), a network (``10.0.0.0/24``) or a host name (its
    addresses, resolved now). ValueError naming the first entry that is none of these."""
    networks = []
    for entry in re.split(r"[\s,;]+", text.strip()):
        if not entry:
            continue
        try:
            networks.append(ipaddress.ip_network(entry, strict=False))
            continue
        except ValueError:
            pass
        try:
            infos = socket.getaddrinfo(entry, None, proto=socket.IPPROTO_TCP)
        except (OSError, UnicodeError):
            raise ValueError(f"{ALLOWED_HOSTS_VAR}: [{entry}] is neither an address, a network "
                             "(10.0.0.0/24) nor a host name this machine can resolve") from None
        for info in infos:
            networks.append(ipaddress.ip_network(str(info[4][0]).split("%", 1)[0]))
    return tuple(networks)


def allowed_hosts(env: Mapping[str, str] | None = None) -> Optional[Tuple[Network, ...]]:
    """ROS_ALLOWED_HOSTS as networks, or None when it is unset or empty: then every peer is
    accepted, as in ROS. ValueError for an entry that is not an address, network or host."""
    env = os.environ if env is None else env
    text = env.get(ALLOWED_HOSTS_VAR, "").strip()
    if not text:
        return None
    return parse_allowed_hosts(text)


def host_allowed(peer: str, allowed: Optional[Sequence[Network]], local: str | None = None) -> bool:
    """Whether a connection from address ``peer`` may be served. Everyone when ``allowed`` is
    None; otherwise loopback, this host itself (``peer`` equal to ``local``, the address the
    connection arrived at) and the members of ``allowed``."""
    if allowed is None:
        return True
    try:
        address = ipaddress.ip_address(peer.split("%", 1)[0])
    except ValueError:
        return False
    mapped = getattr(address, "ipv4_mapped", None)  # ::ffff:10.0.0.1 on a dual-stack socket
    if mapped is not None:
        address = mapped
    if local is not None and peer == local:
        return True
    return any(address in net for net in (*_LOOPBACK, *allowed))
