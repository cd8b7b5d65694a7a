"""The Origin and Host checks of ``minros web`` (minros.web.origin), as header values."""

from __future__ import annotations

import pytest

from minros.web.origin import OriginError, OriginPolicy, normalize, parse_origin, split_values

HOST = "127.0.0.1:9090"


@pytest.mark.parametrize("origin", [
    None,  # roslibpy, scripts, tools: not a page
    "http://127.0.0.1:9090",  # the server's own page
    "http://localhost:3000", "https://localhost", "http://127.0.0.2:8000", "http://[::1]:8080",
    "http://app.localhost:5173",
])
def test_pages_of_this_machine_and_clients_without_origin_are_served(origin):
    assert OriginPolicy().origin_error(origin, HOST) is None


@pytest.mark.parametrize("origin", [
    "http://evil.example", "https://127.0.0.1.evil.example", "http://localhost.evil.example",
    "null", "file://", "chrome-extension://abcdef", "http://127.0.0.1:9091x", "garbage", "",
    "http://robot.example:9091",
])
def test_pages_of_other_sites_are_refused_naming_the_option(origin):
    error = OriginPolicy().origin_error(origin, "robot.example:9090")
    assert error is not None and "--allow-origin" in error and "\n" not in error


def test_the_own_origin_follows_the_host_header():
    policy = OriginPolicy(local_names=["robot"])
    assert policy.origin_error("http://robot:9090", "robot:9090") is None
    assert policy.origin_error("http://robot", "robot") is None  # default ports
    assert policy.origin_error("https://robot", "robot") is None  # behind a TLS proxy
    assert policy.origin_error("http://robot:9091", "robot:9090") is not None
    assert policy.origin_error("http://other:9090", "robot:9090") is not None


def test_allowed_origins_exactly_and_their_names_as_hosts():
    policy = OriginPolicy(["https://app.foxglove.dev", "http://lichtblick.example:8080/"])
    assert policy.origin_error("https://app.foxglove.dev", HOST) is None
    assert policy.origin_error("https://APP.foxglove.dev:443", HOST) is None
    assert policy.origin_error("http://app.foxglove.dev", HOST) is not None  # another scheme
    assert policy.origin_error("https://app.foxglove.dev.evil.example", HOST) is not None
    assert policy.origin_error("http://lichtblick.example:8080", HOST) is None
    assert policy.origin_error("http://lichtblick.example", HOST) is not None
    assert policy.host_error("app.foxglove.dev") is None
    assert policy.cors_origin("https://app.foxglove.dev", HOST) == "https://app.foxglove.dev"
    assert policy.cors_origin("https://evil.example", HOST) is None
    assert policy.cors_origin(None, HOST) is None
    assert OriginPolicy(["null"]).origin_error("null", HOST) is None
    anything = OriginPolicy(["*"])
    assert anything.origin_error("https://evil.example", HOST) is None
    assert anything.host_error("evil.example") is None


@pytest.mark.parametrize("host, ok", [
    (None, True), ("127.0.0.1:9090", True), ("[::1]:9090", True), ("localhost", True),
    ("LOCALHOST.:9090", True), ("x.localhost:9090", True), ("192.168.1.20:9090", True),
    ("robot:9090", True), ("robot.local:9090", True),
    ("evil.example:9090", False), ("localhost.evil.example", False), ("robot.evil", False),
    ("", False), ("a b", False), ("x:notaport", False), ("user@localhost", False),
    ("localhost/path", False),
])
def test_host_names_of_this_machine_addresses_and_loopback_only(host, ok):
    error = OriginPolicy(local_names=["robot", "robot.local"]).host_error(host)
    assert (error is None) is ok, error
    if not ok:
        assert "\n" not in error


def test_allow_origin_values_are_checked_and_normalised():
    assert normalize("https://App.Foxglove.dev/") == "https://app.foxglove.dev:443"
    assert normalize("http://[::1]") == "http://[::1]:80"
    assert normalize("*") == "*" and normalize("null") == "null"
    for bad in ("app.foxglove.dev", "https://app.foxglove.dev/studio", "ftp://x", "https://",
                "https://x:99999"):
        with pytest.raises(OriginError, match="--allow-origin"):
            normalize(bad)
    assert parse_origin("HTTPS://x.example") == ("https", "x.example", 443)
    assert split_values(" https://a.example,https://b.example  null ") == [
        "https://a.example", "https://b.example", "null"]
