// Topics: every topic with its type, publishers, subscribers, rate and bandwidth (measured
// by the server while this view is shown, as rostopic hz/bw would); click one to echo it as a
// collapsible tree (the newest message, at most 10 times a second, long arrays cut).

import {clear, errorLine, formatBytes, formatRate, h, treeView} from "../ui.js";

export function createTopicsView(app) {
  const filter = h("input", {type: "search", placeholder: "filter topics", oninput: () => render()});
  const showDebug = h("input", {type: "checkbox", onchange: () => render()});
  const body = h("tbody");
  const table = h("table", {class: "topics-table"},
    h("thead", {}, h("tr", {}, h("th", {}, "Topic"), h("th", {}, "Type"), h("th", {class: "num"}, "Pubs"),
      h("th", {class: "num"}, "Subs"), h("th", {class: "num"}, "Hz"), h("th", {class: "num"}, "Bandwidth"))),
    body);
  const echoTitle = h("h3", {}, "Echo");
  const echoMeta = h("div", {class: "muted"});
  const echoError = errorLine();
  const tree = treeView(3);
  const hint = h("p", {class: "muted"}, "Click a topic to echo it.");
  const echoPanel = h("aside", {class: "echo-panel"}, echoTitle, echoMeta, echoError, tree, hint);
  const el = h("section", {},
    h("div", {class: "toolbar"}, filter, h("label", {}, showDebug, " debug")),
    h("div", {class: "topics-layout"}, h("div", {class: "table-wrap"}, table), echoPanel));

  let visible = false;
  let echoing = null;
  let timer = null;
  const rows = new Map();  // topic -> {row, hz, bw}

  function listed() {
    const text = filter.value.trim().toLowerCase();
    return app.graph.topics.filter((t) => (showDebug.checked || !app.isQuiet(t.name)) &&
      (!text || t.name.toLowerCase().includes(text) || t.type.toLowerCase().includes(text)));
  }

  function render() {
    const topics = listed();
    clear(body);
    rows.clear();
    for (const topic of topics) {
      const hz = h("td", {class: "num"}, "…");
      const bw = h("td", {class: "num"}, "…");
      const row = h("tr", {class: echoing === topic.name ? "selected" : "", "data-topic": topic.name,
        onclick: () => startEcho(topic.name)},
        h("td", {}, h("code", {}, topic.name)), h("td", {}, topic.type || "?"),
        h("td", {class: "num"}, topic.publishers.length), h("td", {class: "num"}, topic.subscribers.length), hz, bw);
      rows.set(topic.name, {row, hz, bw});
      body.append(row);
    }
    if (visible) app.watchStats("topics", topics.map((t) => t.name));
    updateStats();
  }

  function updateStats() {
    for (const [name, cells] of rows) {
      const stat = app.stats[name];
      if (!stat) continue;
      cells.hz.textContent = formatRate(stat.hz);
      cells.bw.textContent = formatBytes(stat.bw);
    }
  }

  function startEcho(name) {
    stopEcho();
    echoing = name;
    for (const [topic, cells] of rows) cells.row.classList.toggle("selected", topic === name);
    echoTitle.textContent = "Echo " + name;
    hint.hidden = true;
    echoMeta.textContent = "waiting for a message…";
    echoError.show("");
    tree.update({});
    app.conn.request("echo", {id: "echo", topic: name}).catch((err) => echoError.show(err.message));
  }

  function stopEcho() {
    if (echoing) app.conn.send({op: "unecho", id: "echo"});
    echoing = null;
  }

  app.conn.on("echo", (msg) => {
    if (msg.topic !== echoing) return;
    echoMeta.textContent = `${msg.type} · ${msg.count} messages`;
    tree.update(msg.msg);
  });
  app.conn.onOpen(() => { if (echoing && visible) startEcho(echoing); });
  app.onGraph(() => { if (visible) render(); });

  return {
    id: "topics", el,
    show() {
      visible = true;
      render();
      timer = setInterval(updateStats, 1000);
      if (echoing) startEcho(echoing);
    },
    hide() {
      visible = false;
      clearInterval(timer);
      app.watchStats("topics", null);
      const was = echoing;
      stopEcho();
      echoing = was;
    },
    open({echo}) {
      if (echo) startEcho(echo);
    },
  };
}
