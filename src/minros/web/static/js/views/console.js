// Console: /rosout_agg as rqt_console shows it (the last 20,000 lines), filtered by level and
// by a regular expression on the message or node, paused and resumed. Only the rows in view
// exist in the page (a virtual list), so 20,000 lines scroll and filter without freezing.

import {errorLine, fill, h} from "../ui.js";

/** rqt_console's default message limit */
export const MAX_LINES = 20000;
const ROW = 22;
const OVERSCAN = 10;
const LEVELS = [[1, "Debug"], [2, "Info"], [4, "Warn"], [8, "Error"], [16, "Fatal"]];
const LEVEL_NAMES = Object.fromEntries(LEVELS.map(([bit, name]) => [bit, name.toUpperCase()]));

function time(stamp) {
  const d = new Date(stamp * 1000);
  return d.toLocaleTimeString([], {hour12: false}) + "." + String(d.getMilliseconds()).padStart(3, "0");
}

export function createConsoleView(app) {
  const levels = new Set(LEVELS.map(([bit]) => bit));
  const levelBoxes = LEVELS.map(([bit, name]) => h("label", {class: "level-toggle level-" + bit},
    h("input", {type: "checkbox", checked: true, "data-level": name.toLowerCase(), onchange: (e) => {
      if (e.target.checked) levels.add(bit);
      else levels.delete(bit);
      refilter();
    }}), " " + name));
  const regex = h("input", {type: "search", placeholder: "regex on message or node", class: "regex-input", oninput: () => refilter()});
  const regexError = errorLine();
  const pauseButton = h("button", {onclick: () => setPaused(!paused)}, "Pause");
  const counts = h("span", {class: "muted counts"});
  const spacer = h("div", {class: "console-spacer"});
  const rowsBox = h("div", {class: "console-rows"});
  const scroller = h("div", {class: "console-scroll", onscroll: () => schedule()}, spacer, rowsBox);
  const details = h("pre", {class: "console-details"}, "Click a line for its details.");
  const el = h("section", {},
    h("div", {class: "toolbar"}, levelBoxes, regex, pauseButton, h("button", {onclick: () => clearAll()}, "Clear"), counts),
    regexError, scroller, details);

  let lines = [];      // every line kept, oldest first
  let shown = [];      // the lines that pass the filter
  let pending = [];    // lines that arrived while paused
  let pattern = null;
  let paused = false;
  let follow = true;
  let lastSeq = 0;
  let server = null;
  let frame = null;
  let visible = false;

  function matches(line) {
    return levels.has(line[2]) && (!pattern || pattern.test(line[4]) || pattern.test(line[3]));
  }

  function refilter() {
    const text = regex.value;
    try {
      pattern = text ? new RegExp(text, "i") : null;
      regexError.show("");
    } catch (err) {
      regexError.show(`not a regular expression: ${err.message}`);
      return;
    }
    shown = lines.filter(matches);
    follow = true;
    schedule();
  }

  function add(batch) {
    for (const line of batch) lastSeq = Math.max(lastSeq, line[0]);
    if (paused) {
      pending.push(...batch);
      if (pending.length > MAX_LINES) pending.splice(0, pending.length - MAX_LINES);
      schedule();
      return;
    }
    append(batch);
  }

  function append(batch) {
    for (const line of batch) {
      lines.push(line);
      if (matches(line)) shown.push(line);
    }
    if (lines.length > MAX_LINES) {
      const drop = lines.length - MAX_LINES;
      const oldest = lines[drop][0];
      lines.splice(0, drop);
      let cut = 0;
      while (cut < shown.length && shown[cut][0] < oldest) cut++;
      if (cut) shown.splice(0, cut);
    }
    schedule();
  }

  function setPaused(value) {
    paused = value;
    pauseButton.textContent = paused ? "Resume" : "Pause";
    pauseButton.classList.toggle("active", paused);
    if (!paused && pending.length) {
      const batch = pending;
      pending = [];
      append(batch);
    }
    schedule();
  }

  function clearAll() {
    lines = [];
    shown = [];
    pending = [];
    schedule();
  }

  function schedule() {
    if (!frame && visible) frame = requestAnimationFrame(render);
  }

  function render() {
    frame = null;
    spacer.style.height = shown.length * ROW + "px";
    const height = scroller.clientHeight;
    if (follow && !paused) scroller.scrollTop = shown.length * ROW;
    const top = scroller.scrollTop;
    follow = top + height >= shown.length * ROW - ROW;
    const first = Math.max(0, Math.floor(top / ROW) - OVERSCAN);
    const last = Math.min(shown.length, Math.ceil((top + height) / ROW) + OVERSCAN);
    rowsBox.style.transform = `translateY(${first * ROW}px)`;
    const rows = [];
    for (let i = first; i < last; i++) {
      const line = shown[i];
      rows.push(h("div", {class: "console-row level-" + line[2], onclick: () => showDetails(line)},
        h("span", {class: "c-time"}, time(line[1])), h("span", {class: "c-level"}, LEVEL_NAMES[line[2]] || line[2]),
        h("span", {class: "c-node"}, line[3]), h("span", {class: "c-msg"}, line[4])));
    }
    fill(rowsBox, ...rows);
    counts.textContent = `${shown.length} of ${lines.length} lines` + (pending.length ? ` · ${pending.length} new while paused` : "");
  }

  function showDetails(line) {
    const [seq, stamp, level, node, msg, file, func, lineNo, topics] = line;
    details.textContent = `#${seq} ${new Date(stamp * 1000).toISOString()} ${LEVEL_NAMES[level] || level} ${node}\n${msg}\n` +
      `${file}:${func}:${lineNo}\ntopics: ${topics.join(", ")}`;
  }

  app.conn.on("log", (msg) => add(msg.lines));
  app.conn.onOpen(() => {
    const hello = app.conn.hello;
    if (server !== null && hello.started !== server) lastSeq = 0;  // another server: its lines start at 1
    server = hello.started;
    app.conn.send({op: "console", since: lastSeq});
  });

  return {
    id: "console", el,
    show() {
      visible = true;
      follow = true;
      schedule();
    },
    hide() {
      visible = false;
    },
    get state() {
      return {lines: lines.length, shown: shown.length, pending: pending.length, paused};
    },
  };
}
