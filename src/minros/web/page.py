"""The web page's connection: rosbridge v2 plus the ops the page needs that rosbridge lacks.

The page (``minros/web/static``) opens one WebSocket with the subprotocol
:data:`SUBPROTOCOL` (``minros.page.v1``). Its session is a :class:`RosbridgeSession` (every
rosbridge op and rosapi service works as for roslibjs) with these ops added; requests carry an
``id`` and get one ``{"op": "reply", "id", ...}`` (with ``error`` when they failed), streams
are pushed:

=================  ==========================================================================
``graph_watch``    ``graph`` now and whenever the master's graph changes (pushed, see
                   :class:`~minros.web.state.WebState`)
``node_info``      reply: ``rosnode info`` (publications, subscriptions, services, pid,
                   connections)
``stats_watch``    ``{topics}``: ``stats`` (Hz, bandwidth, mean size, count) every second
``plot``           ``{id, expr}`` in rqt_plot's syntax: reply ``series`` names, then
                   ``plot_data`` batches (x, y per series) at most 20 times a second;
                   ``unplot {id}``
``echo``           ``{id, topic}``: ``echo`` with the latest message as a tree (long arrays
                   and strings cut) at most 10 times a second; ``unecho {id}``
``console``        the last 20,000 lines of ``/rosout_agg`` then new ones, as ``log`` batches
``params``         reply: the whole parameter tree; then ``param_changes`` pushes
``param_set``      ``{name, yaml}``: the value typed as YAML; ``param_delete {name}``
``dynrec_get``     ``{server}``: reply the dynamic_reconfigure description (groups, types,
                   ranges, enums) and the current configuration; ``dynrec_set {server,
                   changes}``
``pub_start``      ``{id, topic, type, yaml | msg, rate}``: publish once (rate 0) or at a rate
                   until ``pub_stop {id}``; YAML as ``rostopic pub`` reads it, ``msg`` as
                   rosbridge's publish
``wire_watch``     the steps of the wire traces the server follows (``--trace``), then what
                   changes, as ``wire`` frames: ``steps`` (added or changed, by ``id``),
                   ``removed`` ids, ``status`` (files, problems); the first has ``reset``
``scene_watch``,   the 3D view's: tf into a fixed frame, displays of topics and of the robot
``display_add``,   model, interactive marker feedback (:mod:`minros.web.scene`; clouds, scans
...                and maps come as binary frames)
``learn_list``,    the Learn view's: ``minros learn``'s exercises listed, one started (its
``learn_start``,   fixed programs only, one at a time, stopped when its page asks or goes),
...                its folder's trace followed, an answer checked (:mod:`minros.web.learning`)
=================  ==========================================================================

The first frame the server sends is ``hello`` (node name, how the graph is read, the debug
names the graph hides, whether it follows wire traces and which, whether this page may start
exercises). What the session derives (plot
points, stats, log lines) is computed in ROS threads and only queued; the client's writer
thread encodes and sends, as for every other client (:mod:`minros.web.outbox`).
"""

from __future__ import annotations

import json
import threading
import time
from collections import deque
from typing import Any, Callable, Deque, Dict, Hashable, List, Optional, Tuple

import minros
from minros.tools.master import QUIET_NAMES
from minros.web import pagemodel, plotpath
from minros.web.convert import populate_message
from minros.web.learning import LearnHub, LearnSession
from minros.web.outbox import Outbox
from minros.web.rosapi import Graph
from minros.web.rosbridge import OpError, RosbridgeSession, _check
from minros.web.scene import SceneHub, SceneSession
from minros.web.state import Incoming, WebState, flatten_params
from minros.web.wiretrace import WIRE_BATCH, WireFeed, WireWatch

SUBPROTOCOL = "minros.page.v1"
#: topics one page may ask statistics for at a time
MAX_STATS_TOPICS = 200
#: points one plot keeps for a client that does not read fast enough (the oldest go first)
MAX_PLOT_POINTS = 100_000
#: plots, echoes and publications one page may have running at a time
MAX_PLOTS = 32
MAX_ECHOES = 16
MAX_PUBLISHING = 32
#: dynamic_reconfigure clients the server keeps for pages (the least recently used go first)
MAX_DYNREC_CLIENTS = 32
#: log lines sent in one ``log`` frame
LOG_BATCH = 5_000
PLOT_INTERVAL = 0.05
ECHO_INTERVAL = 0.1
LOG_INTERVAL = 0.1
WIRE_INTERVAL = 0.1
NODE_TIMEOUT = 2.0
DYNREC_TIMEOUT = 3.0
MAX_PUBLISH_RATE = 1000.0
CONSOLE_TOPIC = "/rosout_agg"
LOG_TYPE = "rosgraph_msgs/Log"


class PageHub:
    """What all page sessions of one server share: the console's log ring (one tap on
    ``/rosout_agg``), dynamic_reconfigure clients, the one-second ticker that sends
    statistics, the wire traces followed (``wire``, None without ``--trace``) and the
    exercise started from a page (``learn``, None: this server runs none)."""

    def __init__(self, state: WebState, wire: Optional[WireFeed] = None,
                 learn: Optional[LearnHub] = None) -> None:
        self.state = state
        self.wire = wire
        self.learn = learn
        self.scene = SceneHub(state)
        self.log = pagemodel.LogRing()
        self.sessions: Dict[int, PageSession] = {}
        self.lock = threading.Lock()
        self._console_tapped = False
        self._dynrec: Dict[str, Any] = {}
        self._stop = threading.Event()
        self._ticker: Optional[threading.Thread] = None

    def add(self, session: PageSession) -> None:
        self.start_console()
        with self.lock:
            self.sessions[id(session)] = session
            if self._ticker is None:
                self._ticker = threading.Thread(target=self._tick_loop, name="minros-web-page-tick",
                                                daemon=True)
                self._ticker.start()

    def remove(self, session: PageSession) -> None:
        with self.lock:
            self.sessions.pop(id(session), None)

    def start_console(self) -> None:
        """Tap /rosout_agg once (when the first page connects); the lines are kept while the
        server runs, so a page opened later shows what happened before."""
        with self.lock:
            if self._console_tapped:
                return
            self._console_tapped = True
        self.state.tap(CONSOLE_TOPIC, LOG_TYPE, ("page-console",), self._on_log)

    def _on_log(self, incoming: Incoming) -> None:
        self.log.add(incoming.decoded())
        with self.lock:
            sessions = list(self.sessions.values())
        for session in sessions:
            session.log_arrived()

    def _tick_loop(self) -> None:
        while not self._stop.wait(1.0):
            now = time.monotonic()
            with self.lock:
                sessions = list(self.sessions.values())
            for session in sessions:
                try:
                    session.tick(now)
                except Exception as exc:
                    minros.logerr(f"[web] page statistics failed: {exc}")

    def dynrec_client(self, server: str) -> Any:
        """The dynamic_reconfigure client of ``server`` (created on first use, then kept)."""
        from minros.dynamic_reconfigure.client import Client

        with self.lock:
            client = self._dynrec.pop(server, None)
            if client is not None:
                self._dynrec[server] = client  # now the most recently used
        if client is None:
            # its Subscribers and our taps cannot both hold a topic of the node
            self.state.share_topics([minros.resolve_name(f"{server}/{suffix}") for suffix in
                                     ("parameter_descriptions", "parameter_updates")])
            client = Client(server, timeout=DYNREC_TIMEOUT)
            evicted = []
            with self.lock:
                if server in self._dynrec:
                    evicted.append(client)
                    client = self._dynrec[server]
                else:
                    self._dynrec[server] = client
                    while len(self._dynrec) > MAX_DYNREC_CLIENTS:
                        oldest = next(iter(self._dynrec))
                        evicted.append(self._dynrec.pop(oldest))
            for old in evicted:
                old.close()
        return client

    def forget_dynrec(self, server: str) -> None:
        with self.lock:
            client = self._dynrec.pop(server, None)
        if client is not None:
            client.close()

    def stop(self) -> None:
        self._stop.set()
        with self.lock:
            clients, self._dynrec = list(self._dynrec.values()), {}
            tapped, self._console_tapped = self._console_tapped, False
        for client in clients:
            client.close()
        if tapped:
            self.state.untap(CONSOLE_TOPIC, ("page-console",))
        if self.learn is not None:
            self.learn.close()


class _Plot:
    """One plot request: its series, grouped by topic, and the points not sent yet."""

    def __init__(self, plot_id: Any, fields: List[plotpath.PlotField]) -> None:
        self.id = plot_id
        self.fields = fields
        self.groups = plotpath.group_by_topic(fields)
        self.points: Dict[str, Deque[Tuple[float, List[Optional[float]]]]] = {
            topic: deque(maxlen=MAX_PLOT_POINTS) for topic in self.groups}
        self.lock = threading.Lock()
        self.errors: List[str] = []

    def add(self, topic: str, x: float, values: List[Optional[float]]) -> None:
        with self.lock:
            self.points[topic].append((x, values))

    def drain(self) -> List[Dict[str, Any]]:
        """The points not sent yet, one entry per topic: series indices, x, y per series."""
        out = []
        with self.lock:
            taken = {topic: list(points) for topic, points in self.points.items() if points}
            for points in self.points.values():
                points.clear()
        for topic, points in taken.items():
            series = [index for index, _field in self.groups[topic]]
            out.append({"topic": topic, "series": series, "x": [p[0] for p in points],
                        "y": [[_finite(p[1][i]) for p in points] for i in range(len(series))]})
        return out


def _finite(value: Optional[float]) -> Optional[float]:
    return value if value is not None and value == value and abs(value) != float("inf") else None


class _Publishing:
    """A message published once or at a rate by a page (``pub_start``)."""

    def __init__(self, session: PageSession, pub_id: Any, topic: str, msg: Any,
                 rate: float) -> None:
        self.session = session
        self.id = pub_id
        self.topic = topic
        self.msg = msg
        self.rate = rate
        self.count = 0
        self.stop = threading.Event()
        self.thread: Optional[threading.Thread] = None

    def publish_once(self) -> None:
        pub = self.session.state.publishers.get(self.topic)
        if pub is not None:
            pub.publish(self.msg)
            self.count += 1

    def run(self) -> None:
        period = 1.0 / self.rate
        deadline = time.monotonic()
        while not self.stop.is_set():
            self.publish_once()
            deadline += period
            delay = deadline - time.monotonic()
            if delay < -period:  # fell behind (a suspended laptop): start counting afresh
                deadline = time.monotonic()
                delay = 0
            if self.stop.wait(max(0.0, delay)):
                return


class PageSession(RosbridgeSession):
    """A page's connection: every rosbridge op plus the page's (see the module doc).
    ``local``: the page is of this machine (:meth:`~minros.web.origin.OriginPolicy.local_page`),
    so it may start exercises."""

    def __init__(self, client_id: str, state: WebState, outbox: Outbox,
                 close_client: Callable[[str], None], hub: PageHub, rosapi: Any = None,
                 run_async: Optional[Callable[[Callable[[], None]], None]] = None,
                 local: bool = False) -> None:
        super().__init__(client_id, state, outbox, close_client, rosapi=rosapi, run_async=run_async)
        self.hub = hub
        self.key = ("page", client_id)
        self.stats_topics: Dict[str, pagemodel.TopicMeter] = {}
        self.plots: Dict[Any, _Plot] = {}
        self.echoes: Dict[Any, str] = {}
        self.publishing: Dict[Any, _Publishing] = {}
        self.console_seq: Optional[int] = None
        #: what this page has been sent of the traces the server follows (``wire_watch``)
        self.wire = WireWatch("wire", WIRE_BATCH)
        self.params_watched = False
        self.page_lock = threading.Lock()
        self.ops.update({
            "graph_watch": self.graph_watch, "node_info": self.node_info,
            "stats_watch": self.stats_watch, "plot": self.plot, "unplot": self.unplot,
            "echo": self.echo, "unecho": self.unecho, "console": self.console,
            "params": self.params, "param_set": self.param_set,
            "param_delete": self.param_delete, "dynrec_get": self.dynrec_get,
            "dynrec_set": self.dynrec_set, "pub_start": self.pub_start,
            "pub_stop": self.pub_stop, "wire_watch": self.wire_watch,
        })
        self.scene = SceneSession(self, hub.scene)
        self.ops.update(self.scene.ops)
        self.learn = LearnSession(self, hub.learn, local)
        self.ops.update(self.learn.ops)
        hub.add(self)

    def start(self) -> None:
        self.send({"op": "hello", "protocol": SUBPROTOCOL, "node": minros.get_caller_id(),
                   "graph_mode": self.state.graph_mode, "quiet": list(QUIET_NAMES),
                   "wire": self.hub.wire is not None,
                   "wire_paths": self.hub.wire.specs if self.hub.wire is not None else [],
                   "learn": self.hub.learn is not None and self.learn.local,
                   "version": _version(), "started": self.state.started})

    # -- replies ---------------------------------------------------------------------------

    def reply(self, request: Dict[str, Any], **values: Any) -> None:
        self.send({"op": "reply", "id": request.get("id"), **values})

    def fail(self, request: Dict[str, Any], text: str) -> None:
        self.reply(request, error=text)

    def in_worker(self, request: Dict[str, Any], work: Callable[[], Dict[str, Any]]) -> None:
        """Run ``work`` (which may wait on ROS peers) off the receive thread; reply with what it
        returns, or with its error."""
        def run() -> None:
            try:
                values = work()
            except (OpError, ValueError, LookupError, TypeError, minros.ROSException) as exc:
                self.fail(request, str(exc))
                return
            except Exception as exc:  # a peer's fault: say it next to the input
                self.fail(request, f"{type(exc).__name__}: {exc}")
                return
            if not self._closed:
                self.reply(request, **values)
        self._run_async(run)

    # -- the graph -------------------------------------------------------------------------

    def graph_watch(self, msg: Dict[str, Any]) -> None:
        slot = ("page", "graph")
        self.outbox.open_slot(slot, self._render_graph, maxlen=1)
        self.state.add_graph_listener(self.key, lambda graph: self.outbox.put(slot, graph))
        self.outbox.put(slot, self.state.graph)

    def _render_graph(self, graph: Graph) -> str:
        return json.dumps(pagemodel.graph_json(graph, self.state.graph_version,
                                               self.state.graph_mode))

    def node_info(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "node", (str,))])
        node = msg["node"]

        def work() -> Dict[str, Any]:
            from minros.wire.rosapi import RemoteError
            from minros.wire.slaveapi import SlaveClient

            graph = self.state.graph
            info = pagemodel.node_info(graph, node)
            try:
                uri = self.state._call("lookupNode", node)
            except Exception:
                uri = None
            info["uri"] = uri
            if uri:
                try:
                    with SlaveClient(uri, self.state.caller_id, NODE_TIMEOUT) as client:
                        info["pid"] = client.get_pid()
                        info["connections"] = pagemodel.connections(client.get_bus_info())
                except (OSError, RemoteError) as exc:
                    info["error"] = f"Communication with node[{uri}] failed! ({exc})"
            else:
                info["error"] = f"cannot contact [{node}]: unknown node"
            return {"info": info}
        self.in_worker(msg, work)

    # -- statistics ------------------------------------------------------------------------

    def stats_watch(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "topics", (list,))])
        wanted = [t for t in msg["topics"] if isinstance(t, str) and self.state.topic_allowed(t)]
        wanted = wanted[:MAX_STATS_TOPICS]
        key = (*self.key, "stats")
        with self.page_lock:
            old = set(self.stats_topics)
            for topic in old - set(wanted):
                del self.stats_topics[topic]
            new = [t for t in wanted if t not in old]
            for topic in new:
                self.stats_topics[topic] = pagemodel.TopicMeter()
        for topic in old - set(wanted):
            self.state.untap(topic, key)
        for topic in new:
            self.state.tap(topic, self.state.graph.topic_types.get(topic), key, _ignore)
        self.outbox.open_slot(("page", "stats"), json.dumps, maxlen=1)

    def tick(self, now: float) -> None:
        self.scene.tick()
        with self.page_lock:
            meters = list(self.stats_topics.items())
        if not meters:
            return
        taps = self.state.taps
        stats = {}
        for topic, meter in meters:
            tap = taps.get(topic)
            if tap is not None:
                stats[topic] = meter.sample(now, tap.count, tap.bytes)
        self.outbox.put(("page", "stats"), {"op": "stats", "topics": stats})

    # -- plots -----------------------------------------------------------------------------

    def plot(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "id", (str, int)), (True, "expr", (str,))])
        plot_id = msg["id"]
        try:
            fields = self._plot_fields(msg["expr"])
        except plotpath.PlotPathError as exc:
            self.fail(msg, str(exc))
            return
        self.unplot({"id": plot_id})
        if len(self.plots) >= MAX_PLOTS:
            raise OpError(f"{MAX_PLOTS} plots are running already: remove one first")
        entry = _Plot(plot_id, fields)
        slot = ("page", "plot", plot_id)
        self.outbox.open_slot(slot, lambda _token: self._render_plot(entry), maxlen=1,
                              min_interval=PLOT_INTERVAL)
        with self.page_lock:
            self.plots[plot_id] = entry
        for topic, members in entry.groups.items():
            self.state.tap(topic, self.state.graph.topic_types.get(topic), (*self.key, "plot", plot_id),
                           self._plot_listener(entry, topic, [f for _i, f in members], slot))
        self.reply(msg, series=[f.name for f in fields])

    def _plot_fields(self, expr: str) -> List[plotpath.PlotField]:
        from minros.msgs import get_message_class

        try:
            return plotpath.resolve(expr, self.state.graph.topic_types, get_message_class)
        except plotpath.PlotPathError:
            # a topic that appeared since the last reading of the graph: read it now
            return plotpath.resolve(expr, self.state.refresh_graph().topic_types, get_message_class)

    def _plot_listener(self, entry: _Plot, topic: str, fields: List[plotpath.PlotField],
                       slot: Hashable) -> Callable[[Incoming], None]:
        put = self.outbox.put

        def listener(incoming: Incoming) -> None:
            msg = incoming.decoded()
            try:
                values = [f.value(msg) for f in fields]
            except (AttributeError, TypeError, ValueError) as exc:
                if not entry.errors:
                    entry.errors.append(f"{topic}: {exc}")
                return
            entry.add(topic, plotpath.stamp_of(msg, incoming.receive_ns * 1e-9), values)
            put(slot, None)
        return listener

    def _render_plot(self, entry: _Plot) -> str:
        frame: Dict[str, Any] = {"op": "plot_data", "id": entry.id, "data": entry.drain()}
        if entry.errors:
            frame["error"] = entry.errors.pop()
        return json.dumps(frame)

    def unplot(self, msg: Dict[str, Any]) -> None:
        with self.page_lock:
            entry = self.plots.pop(msg.get("id"), None)
        if entry is None:
            return
        for topic in entry.groups:
            self.state.untap(topic, (*self.key, "plot", entry.id))
        self.outbox.close_slot(("page", "plot", entry.id))

    # -- echo ------------------------------------------------------------------------------

    def echo(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "id", (str, int)), (True, "topic", (str,))])
        echo_id, topic = msg["id"], minros.resolve_name(msg["topic"])
        self._allowed(topic)
        type_name = self.state.topic_type(topic)
        if type_name is None:
            self.fail(msg, f"topic {topic} does not exist (or has no type yet)")
            return
        self.unecho({"id": echo_id})
        if len(self.echoes) >= MAX_ECHOES:
            raise OpError(f"{MAX_ECHOES} echoes are running already: stop one first")
        slot = ("page", "echo", echo_id)
        count = [0]

        def render(incoming: Incoming) -> str:
            return json.dumps({"op": "echo", "id": echo_id, "topic": topic, "count": count[0],
                               "type": incoming.tap.type,
                               "msg": pagemodel.message_tree(incoming.decoded())})

        def listener(incoming: Incoming) -> None:
            count[0] += 1
            self.outbox.put(slot, incoming, incoming.size)
        self.outbox.open_slot(slot, render, maxlen=1, min_interval=ECHO_INTERVAL)
        with self.page_lock:
            self.echoes[echo_id] = topic
        self.state.tap(topic, type_name, (*self.key, "echo", echo_id), listener)
        self.reply(msg, type=type_name)

    def unecho(self, msg: Dict[str, Any]) -> None:
        with self.page_lock:
            topic = self.echoes.pop(msg.get("id"), None)
        if topic is None:
            return
        self.state.untap(topic, (*self.key, "echo", msg.get("id")))
        self.outbox.close_slot(("page", "echo", msg.get("id")))

    # -- the console -----------------------------------------------------------------------

    def console(self, msg: Dict[str, Any]) -> None:
        self.outbox.open_slot(("page", "console"), lambda _token: self._render_log(), maxlen=1,
                              min_interval=LOG_INTERVAL)
        with self.page_lock:
            self.console_seq = int(msg.get("since", 0) or 0)
        self.log_arrived()

    def log_arrived(self) -> None:
        if self.console_seq is not None:
            self.outbox.put(("page", "console"), None)

    def _render_log(self) -> List[str]:
        frames = []
        while True:
            with self.page_lock:
                seq = self.console_seq or 0
            lines = self.hub.log.since(seq)[:LOG_BATCH]
            if not lines:
                break
            with self.page_lock:
                self.console_seq = lines[-1][0]
            frames.append(json.dumps({"op": "log", "lines": lines}))
            if len(lines) < LOG_BATCH:
                break
        return frames

    # -- the wire --------------------------------------------------------------------------

    def wire_watch(self, msg: Dict[str, Any]) -> None:
        feed = self.hub.wire
        if feed is None:
            self.fail(msg, "this server follows no wire trace: start it with 'minros web "
                           "--trace FILE' (FILE written by 'minros trace -o FILE -- ...')")
            return
        slot = ("page", "wire")
        self.outbox.open_slot(slot, lambda _token: self.wire.frames(), maxlen=1,
                              min_interval=WIRE_INTERVAL)
        self.wire.follow(feed)
        feed.listen(self.key, lambda: self.outbox.put(slot, None))
        self.outbox.put(slot, None)

    # -- parameters ------------------------------------------------------------------------

    def params(self, msg: Dict[str, Any]) -> None:
        if not self.params_watched:
            self.params_watched = True
            self.outbox.open_slot(("page", "params"), json.dumps, maxlen=1000)
            self.state.add_param_listener(self.key, self._on_params)

        def work() -> Dict[str, Any]:
            flat: Dict[str, Any] = {}
            flatten_params("", self.state.param_tree(), flat)
            return {"leaves": pagemodel.param_leaves(flat)}
        self.in_worker(msg, work)

    def _on_params(self, changed: Dict[str, Any], removed: List[str]) -> None:
        self.outbox.put(("page", "params"), {"op": "param_changes",
                                             "changed": pagemodel.param_leaves(changed),
                                             "removed": removed})

    def param_set(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "name", (str,)), (True, "yaml", (str,))])
        name = msg["name"].strip()
        if not name.startswith("/"):
            raise OpError(f"parameter names here are global: start {name!r} with /")
        try:
            value = pagemodel.parse_yaml(msg["yaml"])
        except pagemodel.YamlError as exc:
            self.fail(msg, str(exc))
            return
        if value is None:
            self.fail(msg, "an empty value cannot be stored on the parameter server: type a "
                           "value, or delete the parameter")
            return

        def work() -> Dict[str, Any]:
            self.state.set_param(name, value)
            return {"yaml": pagemodel.dumps_yaml(value), "type": pagemodel.yaml_type(value)}
        self.in_worker(msg, work)

    def param_delete(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "name", (str,))])
        name = msg["name"]

        def work() -> Dict[str, Any]:
            try:
                self.state.delete_param(name)
            except KeyError:
                raise LookupError(f"parameter {name} is not set") from None
            return {}
        self.in_worker(msg, work)

    # -- dynamic_reconfigure ---------------------------------------------------------------

    def dynrec_get(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "server", (str,))])
        server = msg["server"]

        def work() -> Dict[str, Any]:
            try:
                client = self.hub.dynrec_client(server)
            except minros.ROSException as exc:
                raise LookupError(f"{server} is not a dynamic_reconfigure server ({exc})") from None
            description = client.get_group_descriptions(DYNREC_TIMEOUT)
            config = client.get_configuration(DYNREC_TIMEOUT)
            if description is None or config is None:
                self.hub.forget_dynrec(server)
                raise LookupError(f"{server} sent no parameter_descriptions/parameter_updates "
                                  f"within {DYNREC_TIMEOUT:g} s")
            return {"groups": _dynrec_group(description),
                    "config": {k: v for k, v in config.items() if k != "groups"}}
        self.in_worker(msg, work)

    def dynrec_set(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "server", (str,)), (True, "changes", (dict,))])

        def work() -> Dict[str, Any]:
            client = self.hub.dynrec_client(msg["server"])
            config = client.update_configuration(dict(msg["changes"]))
            return {"config": {k: v for k, v in config.items() if k != "groups"}}
        self.in_worker(msg, work)

    # -- publishing ------------------------------------------------------------------------

    def pub_start(self, msg: Dict[str, Any]) -> None:
        from minros.msgs.fill import fill_message_args, substitution_keys

        _check(msg, [(True, "id", (str, int)), (True, "topic", (str,)), (True, "type", (str,)),
                     (False, "yaml", (str,)), (False, "msg", (dict,)), (False, "rate", (int, float))])
        topic = minros.resolve_name(msg["topic"])
        self._allowed(topic)
        rate = float(msg.get("rate", 0) or 0)
        if not 0 <= rate <= MAX_PUBLISH_RATE:
            raise OpError(f"rate {rate:g} Hz is out of range: 0 (once) to {MAX_PUBLISH_RATE:g} Hz")
        cls = self._established_class(topic, msg["type"])
        instance = cls()
        if "yaml" in msg:
            try:
                values = pagemodel.parse_yaml(msg["yaml"])
            except pagemodel.YamlError as exc:
                self.fail(msg, str(exc))
                return
            try:
                if values is not None:
                    fill_message_args(instance, [values], substitution_keys(self.state.now()))
            except Exception as exc:  # genpy's MessageException family: the text names the field
                self.fail(msg, f"{cls._type}: {exc}")
                return
        else:
            populate_message(msg.get("msg", {}), instance, self.state.now)
        self.pub_stop({"id": msg["id"]})
        if rate and len(self.publishing) >= MAX_PUBLISHING:
            raise OpError(f"{MAX_PUBLISHING} topics are being published already: stop one first")
        self.state.acquire_publisher(self, topic, cls, queue_size=100)
        self.published.add(topic)
        job = _Publishing(self, msg["id"], topic, instance, rate)
        if rate == 0:
            job.publish_once()
        else:
            with self.page_lock:
                self.publishing[msg["id"]] = job
            job.thread = threading.Thread(target=job.run, name=f"minros-web-pub:{topic}",
                                          daemon=True)
            job.thread.start()
        self.reply(msg, topic=topic, rate=rate)

    def pub_stop(self, msg: Dict[str, Any]) -> None:
        with self.page_lock:
            job = self.publishing.pop(msg.get("id"), None)
        if job is not None:
            job.stop.set()

    # -- the end ---------------------------------------------------------------------------

    def close(self) -> None:
        self.hub.remove(self)
        if self.hub.wire is not None:
            self.hub.wire.unlisten(self.key)
        self.state.remove_graph_listener(self.key)
        if self.params_watched:
            self.state.remove_param_listener(self.key)
        with self.page_lock:
            stats, self.stats_topics = list(self.stats_topics), {}
            plots, echoes = list(self.plots), list(self.echoes)
            jobs, self.publishing = list(self.publishing.values()), {}
        for job in jobs:
            job.stop.set()
        for topic in stats:
            self.state.untap(topic, (*self.key, "stats"))
        for plot_id in plots:
            self.unplot({"id": plot_id})
        for echo_id in echoes:
            self.unecho({"id": echo_id})
        self.scene.close()
        self.learn.close()
        super().close()


def _ignore(incoming: Incoming) -> None:
    """A statistics tap: the tap itself counts messages and bytes."""


def _dynrec_group(group: Dict[str, Any]) -> Dict[str, Any]:
    """A dynamic_reconfigure group tree as the page's form needs it (enums parsed)."""
    from minros.dynamic_reconfigure.client import _enum_constants

    params = []
    for p in group.get("parameters", []):
        entry = {k: p[k] for k in ("name", "type", "min", "max", "default", "description",
                                    "level")}
        entry["enum"] = [{"name": c["name"], "value": c["value"], "description":
                          c.get("description", "")} for c in _enum_constants(p["edit_method"])]
        params.append(entry)
    children = group.get("groups", {})
    children = children.values() if isinstance(children, dict) else children
    return {"name": group.get("name", ""), "type": group.get("type", ""),
            "parameters": params, "groups": [_dynrec_group(g) for g in children]}


def _version() -> str:
    try:
        from importlib.metadata import version

        return version("minros")
    except Exception:
        return "?"
