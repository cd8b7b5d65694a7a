"""relay IN_TOPIC [OUT_TOPIC]: republish every message of IN_TOPIC on OUT_TOPIC
(IN_TOPIC_relay by default), whatever its type.

Parameters (private), as ROS's relay: ``unreliable``; ``lazy`` (subscribe to IN_TOPIC only
while OUT_TOPIC has subscribers: the first message is taken to learn the type, then the input
is dropped until someone subscribes); ``stealth`` (never subscribe because of OUT_TOPIC's own
subscribers: only while ``monitor_topic``, IN_TOPIC by default, has subscribers other than the
relay, checked every ``monitor_rate`` seconds, 1.0), so a relay can feed a topic without being
what keeps its publisher busy. The output is latched when the input's publisher latches.
"""

from __future__ import annotations

import sys
import threading
from typing import Any, List, Optional

import minros
from minros.nodes.topic_tools._common import base_name, init, program_args, usage_error
from minros.topic_tools.shapeshifter import RawOutput

USAGE = "\nusage: relay IN_TOPIC [OUT_TOPIC]\n"


class Relay(minros.SubscribeListener):
    def __init__(self, in_topic: str, out_topic: str) -> None:
        self.in_topic = in_topic
        self.unreliable = bool(minros.get_param("~unreliable", False))
        self.lazy = bool(minros.get_param("~lazy", False))
        self.stealth = bool(minros.get_param("~stealth", False))
        self.lock = threading.Lock()
        self.sub: Any = None
        self.output = RawOutput(out_topic, queue_size=10, subscriber_listener=self)
        if self.stealth:
            self.monitor_topic = minros.resolve_name(minros.get_param("~monitor_topic", in_topic))
            period = float(minros.get_param("~monitor_rate", 1.0))
            minros.Timer(minros.Duration(period), self.check_monitor)
        self.subscribe()

    def subscribe(self) -> None:
        with self.lock:
            if self.sub is None:
                self.sub = minros.Subscriber(self.in_topic, minros.AnyMsg, self.on_message,
                                             tcp_nodelay=not self.unreliable)

    def unsubscribe(self) -> None:
        with self.lock:
            sub, self.sub = self.sub, None
        if sub is not None:
            sub.unregister()

    def on_message(self, msg: Any) -> None:
        self.output.advertise(msg)
        if (self.lazy or self.stealth) and self.output.get_num_connections() == 0:
            minros.logdebug("lazy mode; unsubscribing")
            self.unsubscribe()
            return
        self.output.forward(msg)

    def peer_subscribe(self, topic_name: str, topic_publish: Any, peer_publish: Any) -> None:
        # the first subscriber of the output: a lazy relay takes its input again (a stealth
        # one waits for the monitored topic instead)
        if self.lazy and not self.stealth:
            minros.logdebug("lazy mode; resubscribing")
            self.subscribe()

    def check_monitor(self, event: Any) -> None:
        if not self.output.advertised:
            return
        from minros.tools.master import Master

        me = minros.get_name()
        try:
            _pubs, subs, _srvs = Master(me).system_state()
        except Exception as exc:  # noqa: BLE001 - the master is away: keep as we are
            minros.logerr(f"Failed to communicate with rosmaster: {exc}")
            return
        others = sum(1 for topic, nodes in subs if topic == self.monitor_topic
                     for node in nodes if node != me)
        if others == 0:
            self.unsubscribe()
        else:
            self.subscribe()


def main(argv: Optional[List[str]] = None) -> int:
    args = program_args(argv)
    if len(args) in (1, 2) and args[0] in ("-h", "--help"):
        print(USAGE)
        return 0
    if len(args) not in (1, 2):
        return usage_error(USAGE)
    in_topic = args[0]
    out_topic = args[1] if len(args) == 2 else in_topic + "_relay"
    try:
        name = base_name(in_topic) + "_relay"
    except ValueError as exc:
        return usage_error(USAGE, str(exc))
    init(name, argv)
    Relay(in_topic, out_topic)
    minros.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
