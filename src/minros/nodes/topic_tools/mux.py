"""mux OUT_TOPIC IN_TOPIC1 [IN_TOPIC2 [...]]: forward one selected input to OUT_TOPIC.

Services (in the ``mux`` namespace, which ``mux:=NAME`` renames): ``select``
(topic_tools/MuxSelect; ``__none`` selects no input), ``add``, ``delete``, ``list``; the
latched ``mux/selected`` (std_msgs/String) names the selected input. Parameters:
``~initial_topic`` (the first input by default, ``__none`` for none).
"""

from __future__ import annotations

import sys
import threading
from typing import Any, Dict, List, Optional

import minros
from minros.nodes.topic_tools._common import base_name, init, program_args, usage_error
from minros.topic_tools.policies import NONE_TOPIC, MuxTable
from minros.topic_tools.shapeshifter import RawOutput
from std_msgs.msg import String
from topic_tools.srv import (
    MuxAdd,
    MuxAddResponse,
    MuxDelete,
    MuxDeleteResponse,
    MuxList,
    MuxListResponse,
    MuxSelect,
    MuxSelectResponse,
)

USAGE = "\nusage: mux OUT_TOPIC IN_TOPIC1 [IN_TOPIC2 [...]]\n"


class Mux:
    def __init__(self, out_topic: str, in_topics: List[str], initial: Optional[str]) -> None:
        resolve = minros.resolve_name
        self.table = MuxTable([resolve(t) for t in in_topics],
                              resolve(initial) if initial and initial != NONE_TOPIC else initial)
        self.output = RawOutput(out_topic, queue_size=10)
        self.lock = threading.Lock()
        self.subscribers: Dict[str, Any] = {}
        ns = resolve("mux")
        self.selected_pub = minros.Publisher(f"{ns}/selected", String, queue_size=1, latch=True)
        for topic in self.table.topics:
            self._subscribe(topic)
        self._announce()
        minros.Service(f"{ns}/select", MuxSelect, self.on_select)
        # the service switch_mux calls (ROS's mux keeps it for backward compatibility)
        minros.Service(f"{out_topic}_select", MuxSelect, self.on_select_deprecated)
        minros.Service(f"{ns}/add", MuxAdd, self.on_add)
        minros.Service(f"{ns}/delete", MuxDelete, self.on_delete)
        minros.Service(f"{ns}/list", MuxList, self.on_list)

    def _subscribe(self, topic: str) -> None:
        self.subscribers[topic] = minros.Subscriber(topic, minros.AnyMsg, self.on_message,
                                                    callback_args=topic)

    def _announce(self) -> None:
        self.selected_pub.publish(String(data=self.table.selected or NONE_TOPIC))

    def on_message(self, msg: Any, topic: str) -> None:
        if topic == self.table.selected:
            self.output.forward(msg)

    def on_select(self, req: Any) -> Any:
        with self.lock:
            topic = req.topic if req.topic == NONE_TOPIC else minros.resolve_name(req.topic)
            done, previous = self.table.select(topic)
            if not done:
                raise minros.ServiceException(
                    f"mux has no input {req.topic}: its inputs are {self.table.topics} "
                    "(add it with mux/add)")
            minros.loginfo("mux selected to no input." if topic == NONE_TOPIC
                           else f"mux selected input: [{topic}]")
            self._announce()
            return MuxSelectResponse(prev_topic=previous)

    def on_select_deprecated(self, req: Any) -> Any:
        minros.logwarn("the <topic>_select service is deprecated; use mux/select instead")
        return self.on_select(req)

    def on_add(self, req: Any) -> Any:
        with self.lock:
            if req.topic == NONE_TOPIC:
                raise minros.ServiceException(
                    f"cannot add {NONE_TOPIC}: it is reserved for selecting no input")
            topic = minros.resolve_name(req.topic)
            if topic == minros.resolve_name(self.output.topic):
                raise minros.ServiceException(f"cannot add the mux's own output {topic}")
            if not self.table.add(topic):
                raise minros.ServiceException(
                    f"tried to add a topic that mux was already listening to: [{topic}]")
            self._subscribe(topic)
            minros.loginfo(f"mux added input: [{topic}]")
            return MuxAddResponse()

    def on_delete(self, req: Any) -> Any:
        with self.lock:
            topic = minros.resolve_name(req.topic)
            if topic == self.table.selected:
                # as ROS's mux (ros_comm #2863): the input in use stays until another is selected
                raise minros.ServiceException(
                    f"tried to delete the currently selected topic [{topic}]: select another "
                    f"input (or {NONE_TOPIC}) first")
            if not self.table.delete(topic):
                raise minros.ServiceException(
                    f"tried to delete non-subscribed topic: [{topic}]")
            self.subscribers.pop(topic).unregister()
            minros.loginfo(f"mux deleted input: [{topic}]")
            return MuxDeleteResponse()

    def on_list(self, req: Any) -> Any:
        with self.lock:
            return MuxListResponse(topics=list(self.table.topics))


def main(argv: Optional[List[str]] = None) -> int:
    args = program_args(argv)
    if args[:1] in (["-h"], ["--help"]):
        print(USAGE)
        return 0
    if len(args) < 2:
        return usage_error(USAGE)
    try:
        name = base_name(args[0]) + "_mux"
    except ValueError as exc:
        return usage_error(USAGE, str(exc))
    init(name, argv)
    initial = minros.get_param("~initial_topic", "") or None
    try:
        Mux(args[0], args[1:], initial)
    except ValueError as exc:
        minros.logfatal(str(exc))
        return 1
    minros.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
