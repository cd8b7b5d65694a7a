// Wire: the live wire trace as the numbered sequence ROS courses draw, one list per topic and
// per service: [0] the publisher registers, [1] the subscriber registers, [2] the master says
// who publishes, [3] requestTopic, [4] the publisher's TCPROS address, [5] the TCP connection
// and both connection headers, [6] the messages (services: [0] registerService ... [5] the
// response). The server follows the trace files named by `minros web --trace` (the follow
// logic of `minros trace show --follow`) and pushes `wire` frames: steps added or changed (by
// id), ids to drop (it keeps the newest 5,000), and its status. A step opens to the event's
// details: XML-RPC arguments by name and the [code, status, value] answer, connection headers
// as key=value tables, a frame's bytes and decoded message. Filter by topic, service or node;
// pause to read while the trace goes on (what arrives meanwhile is kept and counted).
//
// The Learn view shows the trace of an exercise's folder with the same view:
// createWireView(app, {op: "learn_wire", watch: null, following, help}) takes the frames of
// another op, leaves the watch to its caller, and is shown while following(status) is true.

import {clear, errorLine, fill, h, treeView} from "../ui.js";

const KIND_RANK = {topic: 0, service: 1, other: 2};
const OTHER_TITLE = "other XML-RPC calls (parameters, graph queries, probes, shutdown)";

function sectionKey(step) {
  return step.kind === "other" ? "other" : `${step.kind} ${step.name}`;
}

function seconds(t, t0) {
  const d = t - t0;
  return (d >= 0 ? "+" : "") + d.toFixed(3);
}

/** A value of an XML-RPC argument, a result or a message: short ones inline, others as a tree. */
function valueCell(value) {
  const text = JSON.stringify(value);
  if (value === null || typeof value !== "object" || text.length <= 100) return h("code", {class: "wire-value"}, text);
  const tree = treeView(1);
  tree.update(value);
  return tree;
}

function table(rows, cls = "") {
  return h("table", {class: "wire-kv " + cls}, h("tbody", {}, rows.map(([key, value]) =>
    h("tr", {}, h("th", {}, key), h("td", {}, value)))));
}

/** A header value: one line as is; a multi-line one (message_definition) by its first line,
 * the whole text one click away. */
function headerValue(value) {
  const lines = value.replace(/\n+$/, "").split("\n");
  if (lines.length < 2) return h("code", {class: "wire-value"}, value);
  return h("div", {}, h("code", {class: "wire-value"}, lines[0]),
    h("details", {}, h("summary", {class: "muted"}, `first line of ${lines.length}: all of it`),
      h("pre", {class: "wire-pre"}, value)));
}

function callDetails(step) {
  const d = step.details;
  const parts = [h("h4", {}, "arguments"),
    d.args.length ? table(d.args.map(([name, value]) => [name, valueCell(value)])) : h("div", {class: "muted"}, "(none)")];
  parts.push(h("h4", {}, "result"));
  if (d.error !== undefined) parts.push(h("div", {class: "error"}, "the call failed: " + d.error));
  else if (d.fault !== undefined) parts.push(h("div", {class: "error"}, "XML-RPC fault: " + d.fault));
  else if (d.code !== undefined) parts.push(table([["code", valueCell(d.code)], ["status", valueCell(d.status)], ["value", valueCell(d.value)]]));
  else parts.push(table([["value", valueCell(d.value)]]));
  parts.push(h("h4", {}, "the call"));
  parts.push(table([
    ["from", `${d.caller} (${d.client || "?"})`],
    ["to", `${d.callee} (${d.uri || d.server || "?"})`],
    ["took", `${d.ms} ms`],
    ["HTTP", d.request_len ? `request ${d.request_len} bytes, response ${d.response_len} bytes` : "?"],
    ["traced by", d.traced_by.join(" and ") + (d.traced_by.length > 1 ? " (both ends)" : " (one end)")],
  ]));
  return parts;
}

function wireDetails(step) {
  const d = step.details;
  const parts = [];
  const ends = [["connection", `${d.client_node} ${d.client} → ${d.server_node} ${d.server} (${d.connection})`]];
  if (d.dir) ends.push(["direction", d.dir]);
  if (step.what === "header") {
    parts.push(h("h4", {}, "connection header"));
    parts.push(table([["length prefix", `${d.prefix} = ${d.len - 4} bytes, then each field as a length and key=value`]]));
    parts.push(table(d.fields.map(([key, value]) => [key, headerValue(value)]), "wire-header"));
  } else if (step.what === "frame") {
    const rows = [["length prefix", `${d.prefix} = ${d.len} bytes`], ["stream offset", String(d.offset)]];
    if (d.ok !== undefined) rows.push(["ok byte", String(d.ok)]);
    rows.push(["body", h("code", {class: "wire-value"}, d.head || "(empty)")]);
    if (d.latency_ms !== undefined) rows.push(["received", `${d.latency_ms} ms after it was sent`]);
    parts.push(h("h4", {}, `frame ${d.n}`), table(rows));
    if (d.msg !== undefined) {
      const tree = treeView(3);
      tree.update(d.msg);
      parts.push(h("h4", {}, "decoded"), tree);
    }
  } else if (step.what === "data") {
    parts.push(table([["bytes", String(d.len)], ["first bytes", h("code", {class: "wire-value"}, d.head)]]));
  } else if (d.stats) {
    parts.push(table(Object.entries(d.stats).map(([key, value]) => [key, String(value)])));
  }
  if (d.probe) ends.push(["probe", "yes: a client asking whether the service is there"]);
  ends.push(["traced by", d.traced_by.join(" and ")]);
  parts.push(h("h4", {}, "the connection"), table(ends));
  return parts;
}

/** "a.jsonl, b.jsonl in /run/dir" when the files share a folder, else their paths. */
function fileList(paths) {
  const folder = (path) => path.includes("/") ? path.slice(0, path.lastIndexOf("/") + 1) : "";
  const dirs = new Set(paths.map(folder));
  if (paths.length < 2 || dirs.size !== 1) return paths.join(", ");
  const [dir] = dirs;
  return paths.map((path) => path.slice(dir.length)).join(", ") + (dir ? ` in ${dir}` : "");
}

/** The Wire view; `options` make another instance of it (see the top of the file). */
export function createWireView(app, options = {}) {
  const op = options.op || "wire";
  const following = options.following || (() => Boolean(app.conn.hello && app.conn.hello.wire));
  const sectionSelect = h("select", {class: "wire-section-select", title: "topic or service", onchange: () => refilter()},
    h("option", {value: ""}, "every topic and service"));
  const nodeSelect = h("select", {class: "wire-node-select", title: "node", onchange: () => refilter()},
    h("option", {value: ""}, "every node"));
  const plumbing = h("input", {type: "checkbox", onchange: () => refilter()});
  const pauseButton = h("button", {class: "wire-pause", onclick: () => setPaused(!paused)}, "Pause");
  const counts = h("span", {class: "muted counts"});
  const source = h("div", {class: "muted wire-source"});
  const problems = h("div", {class: "wire-problems"});
  const notes = h("div", {class: "muted wire-notes"});
  const body = h("div", {class: "wire-body"});
  const help = h("div", {class: "wire-help", hidden: true});
  const toolbar = h("div", {class: "toolbar"}, sectionSelect, nodeSelect,
    h("label", {title: "what every node does (/rosout, the logger services, the master's getPid probes) and this server's own calls"},
      plumbing, " plumbing"),
    pauseButton, counts);
  const el = h("section", {}, toolbar, source, problems, notes, body, help);

  const steps = new Map();     // id -> step
  const sections = new Map();  // key -> {key, kind, name, type, ids: Set, el, list, title, rows: Map, dirty}
  const nodes = new Set();
  const expanded = new Set();
  let status = null;
  let paused = false;
  let missed = 0;              // steps that arrived while paused
  let visible = false;
  let frame = null;
  let dirtyAll = true;

  function section(step) {
    const key = sectionKey(step);
    let sec = sections.get(key);
    if (!sec) {
      const title = h("h3", {class: "wire-title"});
      const list = h("ol", {class: "wire-steps"});
      sec = {key, kind: step.kind, name: step.name, type: "", ids: new Set(), rows: new Map(), title, list, dirty: true,
        el: h("div", {class: "wire-section", "data-section": key}, title, list)};
      sections.set(key, sec);
      dirtyAll = true;
    }
    return sec;
  }

  function receive(msg) {
    if (msg.reset) {
      steps.clear();
      sections.clear();
      nodes.clear();
      clear(body);
      dirtyAll = true;
    }
    for (const id of msg.removed || []) {
      const step = steps.get(id);
      if (!step) continue;
      steps.delete(id);
      expanded.delete(id);
      const sec = sections.get(sectionKey(step));
      if (sec) {
        sec.ids.delete(id);
        sec.rows.delete(id);
        sec.dirty = true;
        if (!sec.ids.size) {
          sections.delete(sec.key);
          dirtyAll = true;
        }
      }
    }
    for (const step of msg.steps) {
      const known = steps.has(step.id);
      steps.set(step.id, step);
      const sec = section(step);
      sec.ids.add(step.id);
      if (step.type && (!sec.type || step.id < sec.typeId)) {  // the first step that names it
        sec.type = step.type;
        sec.typeId = step.id;
      }
      sec.dirty = true;
      for (const node of step.nodes) {
        if (!nodes.has(node) && node !== "?") {
          nodes.add(node);
          dirtyAll = true;
        }
      }
      if (paused && !known) missed++;
    }
    if (msg.status) status = msg.status;
    schedule();
  }

  /** What every node does (/rosout, the logger services, getPid probes) and this server's
   * own calls: hidden unless asked for. */
  function isPlumbing(step) {
    const hello = app.conn.hello;
    return step.plumbing || Boolean(hello && step.nodes.includes(hello.node));
  }

  function shown(step) {
    if (!plumbing.checked && isPlumbing(step)) return false;
    if (sectionSelect.value && sectionKey(step) !== sectionSelect.value) return false;
    if (nodeSelect.value && !step.nodes.includes(nodeSelect.value)) return false;
    return true;
  }

  function refilter() {
    for (const sec of sections.values()) sec.dirty = true;
    dirtyAll = true;
    schedule();
  }

  function setPaused(value) {
    paused = value;
    pauseButton.textContent = paused ? "Resume" : "Pause";
    pauseButton.classList.toggle("active", paused);
    if (!paused) missed = 0;
    schedule(true);
  }

  function schedule(force = false) {
    if (!visible || frame) return;
    if (paused && !force) {
      renderCounts();
      return;
    }
    frame = requestAnimationFrame(render);
  }

  function orderedIds(sec) {
    // calls in time order; each connection's steps together, from where it opened (as
    // `minros trace show` prints a section)
    const ids = [...sec.ids];
    const key = (id) => {
      const s = steps.get(id);
      return s.conn ? s.conn_t : s.t;
    };
    ids.sort((a, b) => key(a) - key(b) || a - b);
    return ids;
  }

  function connectionLabels(ids) {
    const labels = new Map();
    for (const id of ids) {
      const s = steps.get(id);
      if (s.conn && !labels.has(s.conn)) labels.set(s.conn, "#" + (labels.size + 1));
    }
    return labels.size > 1 ? labels : new Map();
  }

  function toggle(step) {
    if (expanded.has(step.id)) expanded.delete(step.id);
    else expanded.add(step.id);
    // only this row is built again: a paused list stays as it is
    const sec = sections.get(sectionKey(step));
    const cached = sec && sec.rows.get(step.id);
    if (!cached) return;
    const li = row(step, cached.label, cached.t0);
    cached.li.replaceWith(li);
    sec.rows.set(step.id, {...cached, li, seq: step.seq});
  }

  function row(step, label, t0) {
    const open = expanded.has(step.id);
    const click = () => toggle(step);
    const number = step.step !== "" ? `[${step.step}]` : "";
    const text = (label ? label + " " : "") + step.text;
    const li = h("li", {class: `wire-step what-${step.what}` + (open ? " open" : ""), "data-id": step.id,
      "data-step": step.step, "data-what": step.what},
      h("div", {class: "wire-line", onclick: click, title: "click for the details"},
        h("span", {class: "wire-no" + (number ? "" : " none")}, number),
        h("span", {class: "wire-time"}, seconds(step.t, t0)),
        h("span", {class: "wire-who"}, step.who),
        h("span", {class: "wire-text"}, text)));
    if (step.what === "call") {
      const reply = step.reply;
      li.append(h("div", {class: "wire-line wire-reply", onclick: click},
        h("span", {class: "wire-no" + (reply.step ? "" : " none")}, reply.step ? `[${reply.step}]` : ""),
        h("span", {class: "wire-time"}, reply.step ? seconds(reply.t, t0) : ""),
        h("span", {class: "wire-who"}, ""),
        h("span", {class: "wire-text"}, reply.text)));
      if (step.count > 1) {
        li.append(h("div", {class: "wire-sub muted"}, h("span", {}, `(and ${step.count - 1} more time${step.count > 2 ? "s" : ""}, the last at ${seconds(step.last, t0)})`)));
      }
    } else if (step.lines.length) {
      const summary = step.what === "header" ? step.lines.join("  ·  ") : step.lines.join("   ");
      li.append(h("div", {class: "wire-sub wire-sub-" + step.what, onclick: click}, h("span", {}, summary)));
    }
    if (open) li.append(h("div", {class: "wire-details"}, step.what === "call" ? callDetails(step) : wireDetails(step)));
    return li;
  }

  function renderSection(sec, t0) {
    const ids = orderedIds(sec).filter((id) => shown(steps.get(id)));
    const labels = connectionLabels(ids);
    const lis = [];
    for (const id of ids) {
      const step = steps.get(id);
      const label = step.conn ? labels.get(step.conn) || "" : "";
      const cached = sec.rows.get(id);
      let li;
      if (cached && cached.seq === step.seq && cached.label === label && cached.t0 === t0) li = cached.li;
      else {
        li = row(step, label, t0);
        sec.rows.set(id, {li, seq: step.seq, label, t0});
      }
      lis.push(li);
    }
    fill(sec.list, ...lis);
    const kindTitle = sec.kind === "other" ? OTHER_TITLE : `${sec.kind} ${sec.name}`;
    fill(sec.title, kindTitle, sec.type ? h("span", {class: "muted"}, ` [${sec.type}]`) : null,
      h("span", {class: "muted wire-count"}, ` · ${ids.length} step${ids.length === 1 ? "" : "s"}`));
    sec.el.hidden = !ids.length;
    sec.dirty = false;
    return ids.length;
  }

  function renderSelects() {
    const keepSection = sectionSelect.value;
    const keepNode = nodeSelect.value;
    const keys = [...sections.values()].filter((s) => plumbing.checked || ![...s.ids].every((id) => isPlumbing(steps.get(id))))
      .sort(sectionOrder).map((s) => s.key);
    fill(sectionSelect, h("option", {value: ""}, "every topic and service"),
      keys.map((key) => h("option", {value: key}, key === "other" ? "other calls" : key)));
    fill(nodeSelect, h("option", {value: ""}, "every node"),
      [...nodes].sort().map((node) => h("option", {value: node}, node)));
    sectionSelect.value = keys.includes(keepSection) ? keepSection : "";
    nodeSelect.value = nodes.has(keepNode) ? keepNode : "";
  }

  function sectionOrder(a, b) {
    const first = (sec) => Math.min(...sec.ids);
    return KIND_RANK[a.kind] - KIND_RANK[b.kind] || first(a) - first(b);
  }

  function renderStatus() {
    const hello = app.conn.hello;
    const on = following(status);
    help.hidden = Boolean(on);
    for (const part of [toolbar, source, problems, notes, body]) part.hidden = !on;
    if (!on) return;
    const paths = status && status.files.length ? status.files : status && status.specs.length ? status.specs : hello.wire_paths;
    source.textContent = status
      ? `following ${fileList(paths)} · ${status.events} events` +
        (status.t0 ? ` · times in seconds from ${new Date(status.t0 * 1000).toLocaleTimeString([], {hour12: false})}` : "")
      : "reading the trace…";
    const lines = status ? status.problems : [];
    fill(problems, lines.map((text) => {
      const line = errorLine();
      line.show(text);
      return line;
    }));
    if (status && !steps.size && !lines.length) {
      problems.append(h("div", {class: "muted"}, "no steps yet: the trace has no XML-RPC call or connection so far"));
    }
    notes.textContent = status ? status.notes.join(" · ") : "";
  }

  function renderCounts() {
    let shownCount = 0;
    for (const step of steps.values()) if (shown(step)) shownCount++;
    counts.textContent = `${shownCount} of ${steps.size} steps` + (paused && missed ? ` · ${missed} new while paused` : "");
  }

  function render() {
    frame = null;
    renderStatus();
    const t0 = status && status.t0 ? status.t0 : 0;
    if (dirtyAll) renderSelects();
    const ordered = [...sections.values()].sort(sectionOrder);
    for (const sec of ordered) if (sec.dirty || dirtyAll) renderSection(sec, t0);
    if (dirtyAll) fill(body, ordered.map((sec) => sec.el));
    dirtyAll = false;
    renderCounts();
  }

  if (options.help) fill(help, options.help);
  else fill(help,
    h("h3", {}, "Wire trace"),
    h("p", {}, "This view shows, live, every XML-RPC call and TCPROS connection header of a running system as the " +
      "numbered sequence ROS courses draw (registerPublisher, registerSubscriber, publisherUpdate, requestTopic, the " +
      "connection headers, the messages). This server follows no trace: start a traced run, then point minros web at it:"),
    h("pre", {class: "wire-pre wire-commands"},
      "minros trace -o run.jsonl -- roslaunch my_pkg my.launch\nminros web --trace run.jsonl"),
    h("p", {class: "muted"}, "Every minros process started under minros trace (or with MINROS_TRACE=FILE in its " +
      "environment) writes its side of the wire to the file; --trace also takes several files, a directory of " +
      "*.jsonl traces or a quoted glob. In a terminal, minros trace show run.jsonl prints the same sequence."));

  app.conn.on(op, receive);
  app.conn.onOpen(() => {
    if (options.watch === undefined && app.conn.hello.wire) app.conn.send({op: "wire_watch"});
    schedule(true);
  });

  return {
    id: options.id || "wire", el,
    show() {
      visible = true;
      dirtyAll = true;
      schedule(true);
    },
    hide() {
      visible = false;
    },
    get state() {
      return {steps: steps.size, sections: sections.size, paused, missed, status};
    },
  };
}
