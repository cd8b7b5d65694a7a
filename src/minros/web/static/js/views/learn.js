// Learn: `minros learn`'s exercises in the page. Pick one, read its task, start it (the server
// starts what `minros learn N` starts: the exercise's master and small nodes, each traced into
// the exercise's folder), do what the task says in a terminal, watch the trace of the folder
// as the Wire view's numbered sequence (yours appears in it as you work), type the answer and
// get right or not yet with a hint. One exercise runs at a time on a server; it stops when
// this page says Stop, when the page has been closed for a few seconds (a reload keeps it:
// the page keeps the run's id in sessionStorage and claims it back), or after minros learn's
// own time limit. Only pages of the server's own machine may start one (see
// minros/web/learning.py).

import {errorLine, fill, h} from "../ui.js";
import {createWireView} from "./wire.js";

const SELECTED = "minros.learn.selected";
const RUN = "minros.learn.run";

function stored(key) {
  try {
    return sessionStorage.getItem(key) || "";
  } catch (err) {
    return "";  // storage refused (a sandboxed page): nothing is remembered
  }
}

function store(key, value) {
  try {
    if (value) sessionStorage.setItem(key, value);
    else sessionStorage.removeItem(key);
  } catch (err) {
    // as above
  }
}

function minutes(seconds) {
  return `${Math.round(seconds / 60)} minutes`;
}

export function createLearnView(app) {
  let exercises = [];
  let folder = "";
  let selected = Number(stored(SELECTED)) || 1;
  let run = null;            // the server's started exercise (a `learn` frame's run), or null
  let verdicts = new Map();  // exercise number -> the last verdict shown
  let busy = false;

  const list = h("ol", {class: "learn-list"});
  const title = h("h3", {class: "learn-title"});
  const about = h("div", {class: "muted learn-about"});
  const startButton = h("button", {class: "primary learn-start", onclick: () => start()}, "Start");
  const stopButton = h("button", {class: "learn-stop", onclick: () => stop()}, "Stop");
  const stateLine = h("div", {class: "learn-state"});
  const errors = errorLine();
  const taskNote = h("div", {class: "muted learn-task-note"});
  const task = h("pre", {class: "wire-pre learn-task"});
  const answer = h("input", {type: "text", class: "learn-answer", autocomplete: "off", spellcheck: "false",
    "aria-label": "your answer"});
  const checkButton = h("button", {type: "submit", class: "learn-check"}, "Check");
  const form = h("form", {class: "row learn-form", onsubmit: (event) => {
    event.preventDefault();
    check();
  }}, answer, checkButton);
  const verdict = h("div", {class: "learn-verdict", role: "status", hidden: true});
  const traceTitle = h("h4", {class: "learn-trace-title"}, "The exercise's trace");
  const trace = createWireView(app, {
    id: "learn-wire", op: "learn_wire", watch: null,
    following: (status) => Boolean(status && status.specs && status.specs.length),
    help: h("p", {class: "muted"}, "The trace of the exercise's folder appears here once it has started: " +
      "what its master and nodes do, and what you do under minros trace."),
  });
  trace.el.classList.add("learn-trace");
  const traceBox = h("div", {class: "learn-trace-box"}, traceTitle, trace.el);
  const localNote = h("div", {class: "learn-local muted", hidden: true});
  const main = h("div", {class: "learn-main"},
    title, about, localNote, h("div", {class: "row learn-run"}, startButton, stopButton, stateLine), errors,
    h("h4", {}, "Task"), taskNote, task,
    h("h4", {}, "Your answer"), form, verdict, traceBox);
  const el = h("section", {}, h("div", {class: "learn-layout"}, list, main));

  function exercise(number) {
    return exercises.find((e) => e.number === number);
  }

  function isLocal() {
    return Boolean(app.conn.hello && app.conn.hello.learn);
  }

  function runOf(number) {
    return run && run.number === number ? run : null;
  }

  function renderList() {
    fill(list, exercises.map((e) => {
      const mark = runOf(e.number) && ["starting", "running", "stopping"].includes(run.state) ? run.state : "";
      return h("li", {class: "learn-item" + (e.number === selected ? " selected" : ""), "data-number": e.number,
        onclick: () => select(e.number)},
        h("span", {class: "learn-no"}, String(e.number)),
        h("span", {class: "learn-name"}, e.title),
        h("span", {class: "muted learn-minutes"}, mark ? mark : `${e.minutes} min`));
    }));
  }

  function processesText(procs) {
    return procs.map((p) => p.status === undefined ? `${p.name} (pid ${p.pid})` : `${p.name} ended (status ${p.status})`).join(", ");
  }

  function renderRun() {
    const e = exercise(selected);
    if (!e) return;
    const mine = runOf(selected);
    const active = mine && ["starting", "running", "stopping"].includes(mine.state);
    const otherActive = run && run.number !== selected && ["starting", "running", "stopping"].includes(run.state);
    const canControl = (r) => r && (r.mine || !r.owned);
    fill(title, `${e.number}. ${e.title}`);
    const covers = e.covers.toLowerCase() === e.title.toLowerCase() ? "" : ` · ${e.covers}`;
    fill(about, `about ${e.minutes} minutes${covers}` +
      (Object.keys(e.planned).length ? ` · ${Object.values(e.planned).join("; ")}` : ""));
    localNote.hidden = isLocal();
    localNote.textContent = "This page may show the exercises but not start them: they start programs on the " +
      "server's machine, so only its own pages and pages on localhost may. Open the page there, or run " +
      `minros learn ${e.number} in a terminal.`;
    startButton.textContent = mine && !active ? "Start again" : "Start";
    startButton.hidden = Boolean(active);
    startButton.disabled = busy || !isLocal() || Boolean(active) ||
      Boolean(otherActive && !canControl(run)) || (run && ["starting", "stopping"].includes(run.state));
    startButton.title = otherActive ? `exercise ${run.number} is ${run.state}` + (canControl(run) ? ": starting this one stops it" : ", started from another page") : "";
    stopButton.hidden = !active;
    stopButton.disabled = busy || !isLocal() || !canControl(mine) || mine.state === "stopping";
    let line = "";
    let cls = "learn-state";
    if (mine) {
      cls += " state-" + mine.state;
      if (mine.state === "starting") line = "starting: " + (e.processes.join(", ") || "nothing to run") + "…";
      else if (mine.state === "running") {
        line = `running: ${processesText(mine.processes)} · it stops by itself after ${minutes(mine.limit)}` +
          (mine.mine ? ", or when this page has been closed for a few seconds" : ", started from another page");
      } else if (mine.state === "ready") line = "ready: this exercise runs nothing; its folder is " + mine.folder;
      else if (mine.state === "stopping") line = "stopping…";
      else if (mine.state === "stopped") line = `stopped (${mine.reason}); its traces stay in ${mine.folder}`;
      else if (mine.state === "failed") line = "it did not start: " + mine.error;
    } else if (otherActive) {
      line = `exercise ${run.number} is ${run.state}` + (run.mine ? " (started from this page)" : run.owned ? " (started from another page)" : "");
    } else {
      line = e.processes.length ? `Start runs ${e.processes.join(", ")}, each traced into ${e.folder}` : `this exercise runs nothing; Start writes its files into ${e.folder}`;
    }
    stateLine.className = cls;
    stateLine.textContent = line;
    if (mine && mine.task) {
      taskNote.textContent = "Run the commands in a terminal on the machine minros web runs on" +
        (mine.env ? ` (first: ${mine.env})` : "") + "; type the answer below instead of minros learn check.";
      task.textContent = mine.task;
      task.classList.remove("preview");
    } else {
      taskNote.textContent = "A preview: the ports, addresses and values marked <…> are chosen when it starts.";
      task.textContent = e.preview;
      task.classList.add("preview");
    }
    answer.placeholder = e.answer_form;
    checkButton.disabled = busy || !isLocal();
    const shown = verdicts.get(selected);
    verdict.hidden = !shown;
    if (shown) renderVerdict(shown);
    traceBox.hidden = !mine || mine.state === "failed" || (mine.state === "ready" && !e.processes.length);
    fill(traceTitle, mine ? `The trace of exercise ${mine.number}: ${mine.folder}` : "");
  }

  function renderVerdict(result) {
    verdict.className = "learn-verdict " + (result.ok ? "right" : "not-yet");
    fill(verdict,
      h("div", {class: "learn-verdict-text"}, h("strong", {}, result.ok ? "Right. " : "Not yet: "),
        result.ok ? result.text.replace(/^Right[.:]?\s*/, "") : result.text),
      result.details.length ? h("pre", {class: "wire-pre learn-details"}, result.details.join("\n")) : null,
      !result.ok && result.hint ? h("div", {class: "learn-hint"}, h("strong", {}, "Hint: "), result.hint) : null);
  }

  function render() {
    renderList();
    renderRun();
  }

  function select(number) {
    selected = number;
    store(SELECTED, String(number));
    errors.show("");
    render();
  }

  async function act(work) {
    busy = true;
    errors.show("");
    render();
    try {
      await work();
    } catch (err) {
      errors.show(err.message);
    } finally {
      busy = false;
      render();
    }
  }

  function start() {
    const number = selected;
    return act(async () => {
      verdicts.delete(number);
      const reply = await app.conn.request("learn_start", {number});
      store(RUN, reply.run);
    });
  }

  function stop() {
    return act(() => app.conn.request("learn_stop"));
  }

  function check() {
    const number = selected;
    const text = answer.value.trim();
    if (!text) {
      errors.show(`Type your answer first (${exercise(number).answer_form}).`);
      return Promise.resolve();
    }
    return act(async () => {
      const result = await app.conn.request("learn_check", {number, answer: text}, 60000);
      verdicts.set(number, result);
    });
  }

  app.conn.on("learn", (msg) => {
    run = msg.run;
    if (run && run.mine && run.run) store(RUN, run.run);
    if (!exercises.length) return;
    render();
  });

  app.conn.onOpen(async () => {
    app.conn.send({op: "learn_watch", ...(stored(RUN) ? {run: stored(RUN)} : {})});
    try {
      const reply = await app.conn.request("learn_list");
      exercises = reply.exercises;
      folder = reply.folder;
      if (!exercise(selected)) selected = exercises.length ? exercises[0].number : 0;
      el.dataset.folder = folder;
      render();
    } catch (err) {
      errors.show(err.message);
    }
  });

  return {
    id: "learn", el,
    show() {
      trace.show();
    },
    hide() {
      trace.hide();
    },
    open(args) {
      if (args.number) select(Number(args.number));
    },
    get state() {
      return {selected, run, exercises: exercises.length, trace: trace.state};
    },
  };
}
