// Graph: nodes (ellipses), topics (boxes) and services (dashed boxes) as rqt_graph draws
// them, laid out left to right by dagre, redrawn when the server pushes a new graph. Debug
// nodes and topics are hidden as rqt_graph's "Hide Debug" hides them. Drag to pan, wheel or
// the +/- buttons to zoom; click a node for `rosnode info`, a topic for its publishers,
// subscribers, type, rate and bandwidth.

import dagre from "../../vendor/dagre/dagre.esm.js";
import {clear, fill, formatBytes, formatRate, h} from "../ui.js";

const SVG = "http://www.w3.org/2000/svg";
const FONT = "12px system-ui, sans-serif";
const LOGGER_SERVICES = ["/get_loggers", "/set_logger_level"];
/** the smallest zoom at which labels can be read on a large screen (on a phone: larger); a
 * first view never zooms out further, the rest of the graph is a drag or the Fit button away */
const READABLE_SCALE = 0.5;
const READABLE_SCALE_PHONE = 0.8;

function s(tag, attrs = {}, ...children) {
  const el = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attrs)) el.setAttribute(key, value);
  for (const child of children) if (child) el.append(child);
  return el;
}

let measureCtx = null;
function textWidth(text) {
  measureCtx = measureCtx || document.createElement("canvas").getContext("2d");
  measureCtx.font = FONT;
  return measureCtx.measureText(text).width;
}

/** What to draw: vertices {id, kind, label} and edges {from, to, kind}. Pure. */
export function graphModel(graph, isQuiet, {debug = false, services = true} = {}) {
  const keep = (name) => debug || !isQuiet(name);
  const vertices = new Map();
  const edges = [];
  const node = (name) => vertices.set("n:" + name, {id: "n:" + name, kind: "node", label: name});
  for (const name of graph.nodes) if (keep(name)) node(name);
  for (const topic of graph.topics) {
    if (!keep(topic.name)) continue;
    const pubs = topic.publishers.filter(keep);
    const subs = topic.subscribers.filter(keep);
    if (!pubs.length && !subs.length) continue;
    const id = "t:" + topic.name;
    vertices.set(id, {id, kind: "topic", label: topic.name, type: topic.type});
    for (const p of pubs) edges.push({from: "n:" + p, to: id, kind: "pub"});
    for (const sub of subs) edges.push({from: id, to: "n:" + sub, kind: "sub"});
  }
  if (services) {
    for (const service of graph.services) {
      if (!keep(service.name)) continue;
      if (!debug && LOGGER_SERVICES.some((suffix) => service.name.endsWith(suffix))) continue;
      const providers = service.providers.filter(keep);
      if (!providers.length) continue;
      const id = "s:" + service.name;
      vertices.set(id, {id, kind: "service", label: service.name});
      for (const p of providers) edges.push({from: "n:" + p, to: id, kind: "srv"});
    }
  }
  return {vertices: [...vertices.values()], edges};
}

export function createGraphView(app) {
  // services make a graph twice as wide: shown by default only where there is room
  const options = {debug: false, services: window.innerWidth > 600};
  const svg = s("svg", {class: "graph-svg", role: "img", "aria-label": "ROS computation graph"});
  const defs = s("defs", {},
    s("marker", {id: "arrow", viewBox: "0 0 10 10", refX: "9", refY: "5", markerWidth: "7", markerHeight: "7", orient: "auto-start-reverse"},
      s("path", {d: "M 0 0 L 10 5 L 0 10 z", class: "arrow-head"})));
  const world = s("g", {class: "world"});
  svg.append(defs, world);
  const info = h("aside", {class: "graph-info", hidden: true});
  const modeNote = h("span", {class: "muted"});
  const toolbar = h("div", {class: "toolbar"},
    h("label", {}, h("input", {type: "checkbox", onchange: (e) => { options.debug = e.target.checked; draw(true); }}), " debug"),
    h("label", {}, h("input", {type: "checkbox", checked: options.services, onchange: (e) => { options.services = e.target.checked; draw(true); }}), " services"),
    h("button", {onclick: () => fit(), title: "show the whole graph"}, "Fit"),
    h("button", {onclick: () => zoomBy(1.25), title: "zoom in"}, "+"),
    h("button", {onclick: () => zoomBy(0.8), title: "zoom out"}, "−"),
    modeNote);
  const canvas = h("div", {class: "graph-canvas"}, svg,
    h("div", {class: "graph-hint muted"}, "Click a node or a topic; drag to move, wheel or +/− to zoom."));
  const el = h("section", {}, toolbar, h("div", {class: "graph-layout"}, canvas, info));

  let transform = {x: 0, y: 0, k: 1};
  let size = {width: 0, height: 0};
  let signature = "";
  let selected = null;
  let fitted = false;
  let visible = false;
  let selectionTimer = null;

  const apply = () => world.setAttribute("transform", `translate(${transform.x},${transform.y}) scale(${transform.k})`);

  /** Show the whole graph; with `readable`, never below READABLE_SCALE (then the graph's
   * start is shown, and the rest is a drag or the Fit button away). */
  function fit(readable = false) {
    const box = canvas.getBoundingClientRect();
    if (!size.width || !box.width) return;
    let k = Math.min(box.width / (size.width + 40), box.height / (size.height + 40), 1.2);
    if (readable) k = Math.max(k, window.innerWidth > 600 ? READABLE_SCALE : READABLE_SCALE_PHONE);
    const place = (room, extent) => (room >= extent * k ? (room - extent * k) / 2 : 10);
    transform = {k, x: place(box.width, size.width), y: place(box.height, size.height)};
    apply();
  }


  function zoomBy(factor, cx, cy) {
    const box = canvas.getBoundingClientRect();
    cx = cx ?? box.width / 2;
    cy = cy ?? box.height / 2;
    const k = Math.max(0.1, Math.min(4, transform.k * factor));
    transform.x = cx - (cx - transform.x) * (k / transform.k);
    transform.y = cy - (cy - transform.y) * (k / transform.k);
    transform.k = k;
    apply();
  }

  canvas.addEventListener("wheel", (event) => {
    event.preventDefault();
    const box = canvas.getBoundingClientRect();
    zoomBy(event.deltaY < 0 ? 1.1 : 1 / 1.1, event.clientX - box.left, event.clientY - box.top);
  }, {passive: false});
  let drag = null;
  canvas.addEventListener("pointerdown", (event) => {
    if (event.target.closest(".vertex")) return;
    drag = {x: event.clientX, y: event.clientY, tx: transform.x, ty: transform.y};
    canvas.setPointerCapture(event.pointerId);
  });
  canvas.addEventListener("pointermove", (event) => {
    if (!drag) return;
    transform.x = drag.tx + event.clientX - drag.x;
    transform.y = drag.ty + event.clientY - drag.y;
    apply();
  });
  canvas.addEventListener("pointerup", () => { drag = null; });

  function layout(model, direction) {
    const g = new dagre.graphlib.Graph();
    // greedy cycle breaking keeps feedback loops (odom -> localization -> planner -> cmd_vel)
    // from stretching the graph into one long row
    g.setGraph({rankdir: direction, acyclicer: "greedy", nodesep: direction === "LR" ? 8 : 16,
                ranksep: direction === "LR" ? 40 : 34, edgesep: 6, marginx: 10, marginy: 10});
    g.setDefaultEdgeLabel(() => ({}));
    for (const v of model.vertices) {
      const w = textWidth(v.label) + (v.kind === "node" ? 30 : 16);
      g.setNode(v.id, {...v, width: w, height: v.kind === "node" ? 28 : 22});
    }
    for (const e of model.edges) g.setEdge(e.from, e.to, {kind: e.kind});
    dagre.layout(g);
    return g;
  }

  function draw(force = false) {
    const graph = app.graph;
    modeNote.textContent = graph.mode === "push" ? "live: the master pushes changes" :
      graph.mode ? "live: read every second (this master cannot push)" : "";
    const model = graphModel(graph, (n) => app.isQuiet(n), options);
    const box = canvas.getBoundingClientRect();
    const sig = JSON.stringify(model);
    if (!force && sig === signature) return;
    signature = sig;
    // left to right as rqt_graph; top to bottom when that fits the window better (a phone)
    const scaleOf = (g) => Math.min(box.width / (g.graph().width + 40), box.height / (g.graph().height + 40));
    let g = layout(model, "LR");
    if (box.height > box.width) {
      const tall = layout(model, "TB");
      if (scaleOf(tall) > scaleOf(g) * 1.1) g = tall;
    }
    const finite = (v) => (Number.isFinite(v) && v > 0 ? v : 0);
    size = {width: finite(g.graph().width), height: finite(g.graph().height)};
    clear(world);
    const edgeLayer = s("g", {class: "edges"});
    const vertexLayer = s("g", {class: "vertices"});
    world.append(edgeLayer, vertexLayer);
    for (const e of g.edges()) {
      const edge = g.edge(e);
      const points = edge.points || [];
      const d = points.map((p, i) => `${i ? "L" : "M"}${p.x.toFixed(1)},${p.y.toFixed(1)}`).join(" ");
      edgeLayer.append(s("path", {d, class: `edge ${edge.kind}`, "data-from": e.v, "data-to": e.w, "marker-end": "url(#arrow)"}));
    }
    for (const id of g.nodes()) {
      const v = g.node(id);
      const group = s("g", {class: `vertex ${v.kind}`, "data-id": id, transform: `translate(${v.x},${v.y})`, tabindex: "0"});
      const shape = v.kind === "node"
        ? s("ellipse", {rx: v.width / 2, ry: v.height / 2})
        : s("rect", {x: -v.width / 2, y: -v.height / 2, width: v.width, height: v.height, rx: v.kind === "service" ? 8 : 2});
      const label = s("text", {"text-anchor": "middle", "dominant-baseline": "central"});
      label.textContent = v.label;
      const title = s("title");
      title.textContent = v.kind === "topic" ? `${v.label} [${v.type || "?"}]` : v.label;
      group.append(title, shape, label);
      group.addEventListener("click", () => select(id));
      group.addEventListener("keydown", (event) => { if (event.key === "Enter") select(id); });
      vertexLayer.append(group);
    }
    if (!fitted || force) {
      fit(true);
      fitted = size.width > 0;
    }
    highlight();
    if (selected && !g.hasNode(selected)) select(null);
    else if (selected) showInfo(selected, false);
  }

  function highlight() {
    for (const el of world.querySelectorAll(".selected, .linked")) el.classList.remove("selected", "linked");
    if (!selected) return;
    const vertex = world.querySelector(`.vertex[data-id="${CSS.escape(selected)}"]`);
    if (vertex) vertex.classList.add("selected");
    for (const edge of world.querySelectorAll(".edge")) {
      if (edge.dataset.from === selected || edge.dataset.to === selected) {
        edge.classList.add("linked");
        const other = edge.dataset.from === selected ? edge.dataset.to : edge.dataset.from;
        const v = world.querySelector(`.vertex[data-id="${CSS.escape(other)}"]`);
        if (v) v.classList.add("linked");
      }
    }
  }

  function select(id) {
    selected = id;
    highlight();
    showInfo(id, true);
  }

  const link = (text, onclick) => h("a", {href: "javascript:void 0", onclick}, text);

  function showInfo(id, fresh) {
    clearInterval(selectionTimer);
    app.watchStats("graph", null);
    info.hidden = !id;
    if (!id) return;
    const close = h("button", {class: "small close", title: "close", onclick: () => select(null)}, "×");
    const name = id.slice(2);
    if (id.startsWith("t:")) {
      const topic = app.graph.topics.find((t) => t.name === name);
      if (!topic) return;
      const rate = h("dd", {}, "…");
      const bw = h("dd", {}, "…");
      fill(info, close,
        h("h3", {}, "Topic ", h("code", {}, name)),
        h("dl", {}, h("dt", {}, "Type"), h("dd", {}, topic.type || "(unknown)"),
          h("dt", {}, "Rate"), rate, h("dt", {}, "Bandwidth"), bw),
        h("h4", {}, "Publishers"), nodeList(topic.publishers),
        h("h4", {}, "Subscribers"), nodeList(topic.subscribers),
        h("p", {}, h("button", {onclick: () => app.open("topics", {echo: name})}, "Echo"), " ",
          h("button", {onclick: () => app.open("plot", {expr: name})}, "Plot"), " ",
          h("button", {onclick: () => app.open("publish", {topic: name, type: topic.type})}, "Publish")));
      app.watchStats("graph", [name]);
      const update = () => {
        const stat = app.stats[name];
        rate.textContent = stat ? `${formatRate(stat.hz)} Hz` : "…";
        bw.textContent = stat ? formatBytes(stat.bw) + (stat.size ? ` (mean ${formatBytes(stat.size, "")})` : "") : "…";
      };
      update();
      selectionTimer = setInterval(update, 1000);
    } else if (id.startsWith("s:")) {
      const service = app.graph.services.find((t) => t.name === name);
      fill(info, close, h("h3", {}, "Service ", h("code", {}, name)),
        h("h4", {}, "Provided by"), nodeList(service ? service.providers : []),
        h("p", {}, h("button", {onclick: () => app.open("services", {service: name})}, "Call")));
    } else {
      if (!fresh && info.dataset.node === name) return;
      info.dataset.node = name;
      fill(info, close, h("h3", {}, "Node ", h("code", {}, name)), h("p", {class: "muted"}, "contacting node…"));
      app.conn.request("node_info", {node: name}).then(({info: data}) => {
        if (selected !== id) return;
        const list = (rows, fmt) => rows.length ? h("ul", {}, rows.map((r) => h("li", {}, fmt(r)))) : h("p", {class: "muted"}, "None");
        const topicLink = ([topic, type]) => [link(topic, () => select("t:" + topic)), h("span", {class: "muted"}, ` [${type || "unknown type"}]`)];
        fill(info, close,
          h("h3", {}, "Node ", h("code", {}, name)),
          h("dl", {}, h("dt", {}, "URI"), h("dd", {}, data.uri || "?"), h("dt", {}, "Pid"), h("dd", {}, data.pid ?? "?")),
          data.error ? h("p", {class: "error"}, data.error) : null,
          h("h4", {}, "Publications"), list(data.publications, topicLink),
          h("h4", {}, "Subscriptions"), list(data.subscriptions, topicLink),
          h("h4", {}, "Services"), list(data.services, (srv) => srv),
          data.connections ? [h("h4", {}, "Connections"), list(data.connections, (c) =>
            `${c.topic} ${c.direction === "outbound" ? "→" : "←"} ${c.to} (${c.transport})`)] : null);
      }).catch((err) => {
        if (selected === id) fill(info, close, h("h3", {}, "Node ", h("code", {}, name)), h("p", {class: "error"}, err.message));
      });
    }
  }

  function nodeList(nodes) {
    if (!nodes.length) return h("p", {class: "muted"}, "None");
    return h("ul", {}, nodes.map((n) => h("li", {}, app.isQuiet(n) ? h("span", {class: "muted"}, n) : link(n, () => select("n:" + n)))));
  }

  app.onGraph(() => { if (visible) draw(); });
  new ResizeObserver(() => { if (visible && !fitted) draw(true); }).observe(canvas);

  return {
    id: "graph", el,
    show() {
      visible = true;
      draw(!fitted);
    },
    hide() {
      visible = false;
      clearInterval(selectionTimer);
      app.watchStats("graph", null);
    },
    select,
  };
}
