"""The dissector generator (pure): what it embeds and how it quotes it. tshark runs the Lua
in tests/integration/test_trace_dissector.py."""

from __future__ import annotations

import re

import pytest

from minros.cli import trace as trace_cli
from minros.tools.trace import dissector


def test_the_template_has_no_types_unless_asked():
    text = dissector.lua_source(version="9.9")
    assert "-- @KNOWN_TYPES@" not in text and "-- (none)" in text
    assert "minros 9.9" in text
    assert 'proto:register_heuristic("tcp", heuristic)' in text


def test_service_and_message_types_are_embedded_with_their_full_texts():
    known = dissector.known_types(["rospy_tutorials/AddTwoInts", "geometry_msgs/PoseStamped"])
    assert set(known.services) == {"rospy_tutorials/AddTwoInts"}
    md5, request, response = known.services["rospy_tutorials/AddTwoInts"]
    assert md5 == "6a2e34150c00229791cc89ff309fff21"
    assert request.strip() == "int64 a\nint64 b" and response.strip() == "int64 sum"
    text = dissector.lua_source(known)
    assert 'KNOWN.services["rospy_tutorials/AddTwoInts"] = {md5 = ' \
           '"6a2e34150c00229791cc89ff309fff21",' in text
    assert "request = [[\nint64 a\nint64 b\n]]" in text
    # a nested type's full text, with its MSG: blocks
    assert re.search(r'KNOWN.messages\["geometry_msgs/PoseStamped"\].*MSG: std_msgs/Header',
                     text, re.S)


def test_a_text_holding_closing_brackets_gets_a_longer_bracket():
    assert dissector._long_string("a]]b") == "[=[\na]]b]=]"
    assert dissector._long_string("a]]b]=]") == "[==[\na]]b]=]]==]"


def test_unknown_types_are_refused_or_left_out():
    with pytest.raises(dissector.UnknownType, match="no_such_pkg/Thing"):
        dissector.known_types(["no_such_pkg/Thing"])
    assert dissector.known_types(["no_such_pkg/Thing"], quiet=True).services == {}


def test_the_service_types_of_a_trace_are_the_servers_header_types():
    events = [
        {"ev": "tcpros.header", "service": "/add", "dir": "in",
         "fields": [["callerid", "/s"], ["service", "/add"], ["type", "rospy_tutorials/AddTwoInts"]]},
        {"ev": "tcpros.header", "topic": "/chatter", "dir": "in",
         "fields": [["type", "std_msgs/String"]]},
        {"ev": "tcpros.header", "service": "/add", "dir": "in",
         "fields": [["type", "rospy_tutorials/AddTwoInts"]]},
        {"ev": "tcpros.header", "service": "/x", "dir": "out", "fields": [["md5sum", "*"]]},
    ]
    assert dissector.types_in_events(events) == ["rospy_tutorials/AddTwoInts"]


def test_the_command_writes_the_file_and_names_an_unknown_type_in_one_line(tmp_path, capsys):
    out = tmp_path / "m.lua"
    assert trace_cli.main(["dissector", "-o", str(out), "--type", "std_srvs/Trigger"]) == 0
    assert 'KNOWN.services["std_srvs/Trigger"]' in out.read_text()
    assert "tshark -X lua_script:" in capsys.readouterr().out
    assert trace_cli.main(["dissector", "-o", str(out), "--type", "nope/Nope"]) == 1
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "nope/Nope" in err and "rosmsg show" in err
    assert trace_cli.main(["dissector", "-o", str(tmp_path / "no" / "m.lua")]) == 1
    assert "cannot write" in capsys.readouterr().err
