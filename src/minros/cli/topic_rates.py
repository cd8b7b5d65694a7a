"""``rostopic hz``, ``bw`` and ``delay``: statistics over a window of received messages,
printed once a second."""

from __future__ import annotations

import argparse
import math
import sys
import threading
import time
from typing import Any, Dict, List, Tuple

from minros.cli.topic_common import (
    NAME,
    checked_master,
    compile_filter,
    init_tool_node,
    ros_now,
    wait_topic_type,
)
from minros.tools.common import flush_stdout, option_parser, resolve
from minros.tools.master import Master, MasterError


class HzStats:
    """Message inter-arrival statistics over a window (rostopic hz)."""

    def __init__(self, window_size: int = -1) -> None:
        self.window = window_size if window_size >= 0 else 50000
        self.lock = threading.Lock()
        self.t0 = -1.0
        self.tn = 0.0
        self.last_printed = 0.0
        self.times: List[float] = []

    def tick(self, now: float) -> None:
        with self.lock:
            if self.t0 < 0 or self.t0 > now:
                self.t0 = self.tn = now
                self.times = []
            else:
                self.times.append(now - self.tn)
                self.tn = now
            if len(self.times) > self.window - 1:
                del self.times[0:len(self.times) - max(self.window - 1, 0)]

    def get(self) -> Tuple[float, float, float, float, int] | None:
        with self.lock:
            if not self.times or self.tn == self.last_printed:
                return None
            n = len(self.times)
            mean = sum(self.times) / n
            rate = 1.0 / mean if mean > 0.0 else 0.0
            std = math.sqrt(sum((x - mean) ** 2 for x in self.times) / n)
            self.last_printed = self.tn
            return rate, min(self.times), max(self.times), std, n + 1


def _ascii_table(header: List[str], cols: Dict[str, List[str]]) -> str:
    widths = []
    aligned = []
    for h in header:
        width = max(len(h), max(len(c) for c in cols[h]))
        widths.append(width)
        aligned.append(h.center(width))
        cols[h] = [c.ljust(width) for c in cols[h]]
    total = sum(widths) + 3 * (len(header) - 1)
    rows = len(cols[header[0]])
    body = "\n".join("   ".join(cols[h][i] for h in header) for i in range(rows))
    return "{}\n{}\n{}\n".format("   ".join(aligned), "=" * total, body)


def _use_sim_time(master: Master) -> bool:
    try:
        return bool(master.getParam("/use_sim_time"))
    except MasterError:
        return False


def hz_cmd(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [options] /topic_0 [/topic_1 [topic_2 [..]]]")
    p.add_option("-w", "--window", dest="window_size", default="-1", metavar="WINDOW",
                 help="window size, in # of messages, for calculating rate")
    p.add_option("--filter", dest="filter_expr", default=None, metavar="EXPR",
                 help="only measure messages matching the specified Python expression")
    p.add_option("--wall-time", dest="use_wtime", default=False, action="store_true",
                 help="calculates rate using wall time which can be helpful when clock isn't published during simulation")
    p.add_option("--tcpnodelay", dest="tcp_nodelay", default=False, action="store_true",
                 help="use the TCP_NODELAY transport hint when subscribing to topics")
    args, names_given = p.parse_args(argv)
    if not names_given:
        p.error("topic must be specified")
    try:
        window = int(args.window_size)
    except ValueError:
        p.error("window size must be an integer")
    topics = [resolve(NAME, t) for t in names_given]
    filter_fn = compile_filter(args.filter_expr)
    master = checked_master()
    init_tool_node()
    from minros.client.topics import AnyMsg, Subscriber
    from minros.tools.decode import Decoder

    sim = _use_sim_time(master) and not args.use_wtime
    stats = {t: HzStats(window) for t in topics}
    decoder = Decoder()
    for topic in topics:
        _type, real_topic, _field = wait_topic_type(master, topic)

        def callback(raw: Any, topic: str = topic) -> None:
            if filter_fn is not None:
                try:
                    if not filter_fn(decoder.decode(raw), topic):
                        return
                except Exception:
                    return
            stats[topic].tick(ros_now().to_sec() if sim else time.time())

        Subscriber(real_topic, AnyMsg, callback, tcp_nodelay=args.tcp_nodelay)
        print(f"subscribed to [{real_topic}]")
    if sim:
        sys.stderr.write("WARNING: may be using simulated time\n")
    flush_stdout()
    from minros import node

    while not node.wait_for_shutdown(1.0):
        if len(topics) == 1:
            result = stats[topics[0]].get()
            if result is None:
                print("no new messages")
            else:
                rate, mn, mx, std, n = result
                print(f"average rate: {rate:.3f}\n\tmin: {mn:.3f}s max: {mx:.3f}s std dev: {std:.5f}s window: {n}")
        else:
            header = ["topic", "rate", "min_delta", "max_delta", "std_dev", "window"]
            cols: Dict[str, List[str]] = {h: [] for h in header}
            for topic in topics:
                result = stats[topic].get()
                if result is None:
                    continue
                rate, mn, mx, std, n = result
                cols["topic"].append(topic)
                cols["rate"].append(f"{rate:.4}")
                cols["min_delta"].append(f"{mn:.4}")
                cols["max_delta"].append(f"{mx:.4}")
                cols["std_dev"].append(f"{std:.4}")
                cols["window"].append(str(n))
            print(_ascii_table(header, cols) if cols["topic"] else "no new messages")
        flush_stdout()
    return 0


def format_bw(sizes: List[int], times: List[float], now: float) -> str | None:
    n = len(times)
    if n < 2:
        return None
    total = sum(sizes)
    per_s = total / (now - times[0])
    mean = total / n
    values = [per_s, mean, min(sizes), max(sizes)]
    if per_s < 1000:
        bw, mean_s, min_s, max_s = [f"{v:.2f}B" for v in values]
    elif per_s < 1000000:
        bw, mean_s, min_s, max_s = ["%.2fKB" % (v / 1000) for v in values]
    else:
        bw, mean_s, min_s, max_s = ["%.2fMB" % (v / 1000000) for v in values]
    return f"average: {bw}/s\n\tmean: {mean_s} min: {min_s} max: {max_s} window: {n}"


def bw_cmd(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " /topic")
    p.add_option("-w", "--window", dest="window_size", default=None, metavar="WINDOW",
                 help="window size, in # of messages, for calculating rate")
    args, topics = p.parse_args(argv)
    if not topics:
        p.error("topic must be specified")
    if len(topics) > 1:
        p.error("you may only specify one input topic")
    try:
        window = int(args.window_size) if args.window_size is not None else 100
    except ValueError:
        p.error("window size must be an integer")
    window = window or 100
    topic = resolve(NAME, topics[0])
    master = checked_master()
    _type, real_topic, _field = wait_topic_type(master, topic)
    init_tool_node()
    from minros.client.topics import AnyMsg, Subscriber

    lock = threading.Lock()
    sizes: List[int] = []
    times: List[float] = []

    def callback(raw: Any) -> None:
        with lock:
            times.append(time.time())
            sizes.append(len(raw._buff))
            if len(times) > window:
                del times[0]
                del sizes[0]

    Subscriber(real_topic, AnyMsg, callback)
    print(f"subscribed to [{real_topic}]")
    flush_stdout()
    from minros import node

    while not node.wait_for_shutdown(1.0):
        with lock:
            text = format_bw(list(sizes), list(times), time.time())
        if text:
            print(text)
            flush_stdout()
    return 0


def delay_cmd(argv: List[str], prog: str) -> int:
    # rostopic parses 'delay' with argparse, its errors naming only the tool
    tool = prog.rsplit(" ", 1)[0]
    p = argparse.ArgumentParser(usage=f"{prog} [options] /topic", prog=tool)
    p.add_argument("topic", help="topic name to be calcurated the delay")
    p.add_argument("-w", "--window", dest="window_size", default=-1, type=int,
                   help="window size, in # of messages, for calculating rate")
    p.add_argument("--tcpnodelay", dest="tcp_nodelay", action="store_true",
                   help="use the TCP_NODELAY transport hint when subscribing to topics")
    args = p.parse_args(argv)
    topic = resolve(NAME, args.topic)
    master = checked_master()
    _type, real_topic, _field = wait_topic_type(master, topic)
    init_tool_node()
    from minros.client.topics import AnyMsg, Subscriber
    from minros.tools.decode import Decoder

    decoder = Decoder()
    window = args.window_size if args.window_size >= 0 else 50000
    lock = threading.Lock()
    delays: List[float] = []
    state = {"t0": -1.0, "tn": 0.0, "last": 0.0, "warned": False}

    def callback(raw: Any) -> None:
        msg = decoder.decode(raw)
        if not getattr(msg, "_has_header", False):
            if not state["warned"]:
                sys.stderr.write("msg does not have header\n")
                state["warned"] = True
            return
        now = ros_now()
        with lock:
            cur = now.to_sec()
            if state["t0"] < 0 or state["t0"] > cur:
                state["t0"] = state["tn"] = cur
                delays.clear()
            else:
                delays.append(cur - msg.header.stamp.to_sec())
                state["tn"] = cur
            if len(delays) > window - 1:
                del delays[0]

    Subscriber(real_topic, AnyMsg, callback, tcp_nodelay=args.tcp_nodelay)
    print(f"subscribed to [{real_topic}]")
    flush_stdout()
    from minros import node

    while not node.wait_for_shutdown(1.0):
        with lock:
            if not delays:
                continue
            if state["tn"] == state["last"]:
                print("no new messages")
                continue
            n = len(delays)
            mean = sum(delays) / n
            std = math.sqrt(sum((x - mean) ** 2 for x in delays) / n)
            state["last"] = state["tn"]
            text = (f"average delay: {mean:.3f}\n\tmin: {min(delays):.3f}s max: {max(delays):.3f}s "
                    f"std dev: {std:.5f}s window: {n + 1}")
        print(text)
        flush_stdout()
    return 0
