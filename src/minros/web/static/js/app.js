// The page: one connection, the graph every view reads, a menu, and the views.
//
// The address's hash names the view: #graph, #topics, ... Two views side by side (on a wide
// screen; stacked on a phone): #plot+images. Each view module exports a function
// create(app) -> {id, title, el, show(), hide(), open?(args)}; a view is built the first
// time it is shown and kept (a plot keeps collecting while another view is shown).

import {Connection} from "./conn.js";
import {h} from "./ui.js";
import {createGraphView} from "./views/graph.js";
import {createTopicsView} from "./views/topics.js";
import {createPlotView} from "./views/plot.js";
import {createImagesView} from "./views/images.js";
import {createView3dView} from "./views/view3d.js";
import {createTurtlesimView} from "./views/turtlesim.js";
import {createParamsView} from "./views/params.js";
import {createServicesView} from "./views/services.js";
import {createPublishView} from "./views/publish.js";
import {createConsoleView} from "./views/console.js";
import {createWireView} from "./views/wire.js";
import {createLearnView} from "./views/learn.js";
import {createAboutView} from "./views/about.js";

const VIEWS = [
  ["graph", "Graph", createGraphView],
  ["topics", "Topics", createTopicsView],
  ["plot", "Plot", createPlotView],
  ["images", "Images", createImagesView],
  ["3d", "3D", createView3dView],
  ["turtlesim", "Turtlesim", createTurtlesimView],
  ["params", "Parameters", createParamsView],
  ["services", "Services", createServicesView],
  ["publish", "Publish", createPublishView],
  ["console", "Console", createConsoleView],
  ["wire", "Wire", createWireView],
  ["learn", "Learn", createLearnView],
  ["about", "About", createAboutView],
];

class App {
  constructor() {
    this.conn = new Connection();
    this.graph = {nodes: [], topics: [], services: [], mode: "", version: 0};
    this.graphListeners = new Set();
    this.views = new Map();
    this.shown = [];
    this.statsWanted = new Map();  // watcher -> topics
    this.stats = {};               // topic -> {hz, bw, size, count}
    this.buildShell();
    this.conn.on("state", ({state}) => this.showState(state));
    this.conn.on("graph", (graph) => this.setGraph(graph));
    this.conn.onOpen(() => {
      this.conn.send({op: "graph_watch"});
      this.statsSent = null;  // a new session measures nothing yet
      this.sendStatsWatch();
    });
    this.conn.on("stats", (msg) => Object.assign(this.stats, msg.topics));
    window.addEventListener("hashchange", () => this.route());
    this.view("console");  // collects /rosout_agg from the start, shown or not
    this.route();
  }

  buildShell() {
    this.status = h("span", {class: "status connecting", title: "connection to minros web"}, "connecting…");
    this.summary = h("span", {class: "summary"});
    this.nav = h("nav", {class: "menu"}, VIEWS.map(([id, title]) =>
      h("a", {href: "#" + id, "data-view": id, onclick: (event) => {
        if (event.shiftKey || event.ctrlKey || event.metaKey) {  // open beside the current view
          event.preventDefault();
          const current = this.shown.filter((v) => v !== id).slice(0, 1);
          location.hash = [...current, id].join("+");
        }
      }}, title)));
    this.main = h("main", {class: "views"});
    document.body.append(
      h("header", {class: "top"}, h("a", {class: "brand", href: "#graph"}, "minros"), this.summary, this.status),
      this.nav, this.main);
  }

  showState(state) {
    const connected = state === "connected";
    this.status.className = "status " + (connected ? "connected" : "disconnected");
    this.status.textContent = connected ? "connected" : "reconnecting…";
    document.body.classList.toggle("offline", !connected);
  }

  setGraph(graph) {
    this.graph = graph;
    this.topicTypes = new Map(graph.topics.map((t) => [t.name, t.type]));
    const count = (names) => names.filter((n) => !this.isQuiet(n)).length;
    const how = graph.mode === "push" ? "pushed by the master" : "read every second (rosmaster)";
    this.summary.textContent = `${count(graph.nodes)} nodes · ${count(graph.topics.map((t) => t.name))} topics · ` +
      `${count(graph.services.map((s) => s.name))} services`;
    this.summary.title = `graph ${how}`;
    for (const cb of [...this.graphListeners]) cb(graph);
  }

  /** cb(graph) now and on every graph push; returns a function that stops it. */
  onGraph(cb) {
    this.graphListeners.add(cb);
    if (this.graph.version) cb(this.graph);
    return () => this.graphListeners.delete(cb);
  }

  /** rqt_graph's "Hide Debug": /rosout, /rosapi, rqt, ... and this server's own node. */
  isQuiet(name) {
    const hello = this.conn.hello;
    if (!hello) return false;
    if (name === hello.node) return true;
    return hello.quiet.some((q) => name.includes(q));
  }

  /** Ask for the Hz and bandwidth of `topics` (null: stop) on behalf of `watcher`; the
   * server measures the union of what every watcher wants. Values land in app.stats. */
  watchStats(watcher, topics) {
    if (topics && topics.length) this.statsWanted.set(watcher, topics);
    else this.statsWanted.delete(watcher);
    this.sendStatsWatch();
  }

  sendStatsWatch() {
    const union = new Set();
    for (const topics of this.statsWanted.values()) for (const t of topics) union.add(t);
    const list = [...union].sort();
    const key = list.join("\n");
    if (key === this.statsSent && this.conn.state === "connected") return;
    if (this.conn.send({op: "stats_watch", topics: list})) this.statsSent = key;
  }

  topicType(name) {
    return this.topicTypes ? this.topicTypes.get(name) || "" : "";
  }

  view(id) {
    let view = this.views.get(id);
    if (!view) {
      const entry = VIEWS.find(([key]) => key === id);
      if (!entry) return null;
      view = entry[2](this);
      view.el.classList.add("view", "view-" + id);
      view.el.dataset.view = id;
      this.views.set(id, view);
      this.main.append(view.el);
    }
    return view;
  }

  route() {
    const wanted = location.hash.replace(/^#/, "").split("+").filter((id) => VIEWS.some(([key]) => key === id));
    const ids = wanted.length ? wanted.slice(0, 2) : ["graph"];
    for (const id of this.shown) {
      if (!ids.includes(id)) {
        const view = this.views.get(id);
        view.el.classList.remove("shown");
        view.hide();
      }
    }
    this.main.classList.toggle("split", ids.length > 1);
    ids.forEach((id, index) => {
      const view = this.view(id);
      view.el.style.order = index;
      if (!this.shown.includes(id)) {
        view.el.classList.add("shown");
        view.show();
      }
    });
    this.shown = ids;
    for (const link of this.nav.querySelectorAll("a")) link.classList.toggle("active", ids.includes(link.dataset.view));
    document.title = ids.map((id) => VIEWS.find(([key]) => key === id)[1]).join(" + ") + " · minros web";
  }

  /** Show view `id` and hand it `args` (e.g. open("plot", {expr: "/a/x"})). */
  open(id, args) {
    const view = this.view(id);
    if (!this.shown.includes(id)) location.hash = id;
    if (view.open) view.open(args || {});
  }
}

window.minrosPage = new App();
