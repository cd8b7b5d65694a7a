// Plot: numeric fields by path with rqt_plot's syntax (/turtle1/pose/x, /turtle1/pose/x:y,
// several paths separated by spaces or commas; a message plots its numeric fields). The
// server resolves the paths (errors appear under the input) and sends the values in batches;
// the chart (uPlot) redraws at most once per animation frame. x is seconds since the first
// point: the header stamp when the message has one, else its arrival (rqt_plot's rule).
// Pause freezes the view (points keep arriving); drag to zoom, double-click to follow again.

import uPlot from "../../vendor/uplot/uPlot.esm.js";
import {errorLine, fill, h} from "../ui.js";

const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#17becf", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22"];
/** seconds of points kept per series (the longest window offered) */
const KEEP_SECONDS = 60;
/** points kept per series whatever the window (a 1 kHz topic for 60 s) */
const KEEP_POINTS = 60_000;

export function createPlotView(app) {
  const input = h("input", {type: "text", class: "plot-input", placeholder: "/turtle1/pose/x  or  /turtle1/pose/x:y",
    list: "plot-topics", onkeydown: (e) => { if (e.key === "Enter") add(); }});
  const error = errorLine();
  const pauseButton = h("button", {onclick: () => setPaused(!paused)}, "Pause");
  const windowSelect = h("select", {onchange: () => { follow = true; dirty = true; }},
    [10, 30, 60].map((s) => h("option", {value: s, selected: s === 10}, `${s} s`)));
  const seriesList = h("ul", {class: "series-list"});
  const chartBox = h("div", {class: "chart"});
  const note = h("div", {class: "muted plot-note"}, "Drag on the chart to zoom, double-click to follow the newest points again.");
  const el = h("section", {},
    h("div", {class: "toolbar"}, input, h("button", {onclick: () => add()}, "Add"), pauseButton,
      h("button", {onclick: () => clearData()}, "Clear"), h("label", {}, "window ", windowSelect)),
    error, seriesList, chartBox, note);

  const series = [];       // {name, plotId, index, xs, ys, color}
  const plots = new Map(); // plotId -> expr
  let t0 = null;
  let chart = null;
  let paused = false;
  let follow = true;
  let dirty = false;
  let visible = false;
  let frame = null;
  let ownScale = false;
  let colorIndex = 0;

  function setPaused(value) {
    paused = value;
    pauseButton.textContent = paused ? "Resume" : "Pause";
    pauseButton.classList.toggle("active", paused);
    dirty = true;
  }

  async function add(exprText) {
    const expr = (exprText ?? input.value).trim();
    if (!expr) {
      error.show("type a field path, e.g. /turtle1/pose/x");
      return;
    }
    const plotId = app.conn.newId("plot");
    try {
      const reply = await app.conn.request("plot", {id: plotId, expr});
      error.show("");
      plots.set(plotId, expr);
      reply.series.forEach((name, index) => {
        series.push({name, plotId, index, xs: [], ys: [], color: COLORS[colorIndex++ % COLORS.length]});
      });
      if (exprText === undefined) input.value = "";
      rebuild();
    } catch (err) {
      error.show(err.message);
    }
  }

  function remove(entry) {
    series.splice(series.indexOf(entry), 1);
    if (!series.some((s) => s.plotId === entry.plotId)) {
      app.conn.send({op: "unplot", id: entry.plotId});
      plots.delete(entry.plotId);
    }
    rebuild();
  }

  function clearData() {
    for (const s of series) {
      s.xs.length = 0;
      s.ys.length = 0;
    }
    t0 = null;
    follow = true;
    dirty = true;
  }

  function rebuild() {
    fill(seriesList, ...series.map((s) => h("li", {},
      h("span", {class: "swatch", style: {background: s.color}}), h("code", {}, s.name), " ",
      h("button", {class: "small", title: "remove", onclick: () => remove(s)}, "×"))));
    if (chart) chart.destroy();
    chart = null;
    if (!series.length) return;
    const box = chartBox.getBoundingClientRect();
    chart = new uPlot({
      mode: 2,
      width: Math.max(200, box.width),
      height: Math.max(200, box.height || 360),
      legend: {show: false},
      cursor: {drag: {x: true, y: true, setScale: true}},
      scales: {x: {time: false, auto: false}, y: {auto: true}},
      axes: [{label: "seconds"}, {}],
      series: [{}, ...series.map((s) => ({label: s.name, stroke: s.color, width: 1.5,
        paths: uPlot.paths.linear(), points: {show: false}, facets: [{scale: "x", auto: false}, {scale: "y", auto: true}]}))],
      hooks: {
        setScale: [(u, key) => { if (key === "x" && !ownScale) follow = false; }],
      },
    }, [null, ...series.map((s) => [s.xs, s.ys])], chartBox);
    chart.over.addEventListener("dblclick", () => { follow = true; dirty = true; });
    dirty = true;
  }

  function onData(msg) {
    if (msg.error) error.show(msg.error);
    for (const batch of msg.data) {
      const xs = batch.x;
      if (!xs.length) continue;
      if (t0 === null) t0 = xs[0];
      for (const s of series) {
        if (s.plotId !== msg.id) continue;
        const column = batch.series.indexOf(s.index);
        if (column < 0) continue;
        const ys = batch.y[column];
        for (let i = 0; i < xs.length; i++) {
          if (ys[i] === null) continue;
          s.xs.push(xs[i] - t0);
          s.ys.push(ys[i]);
        }
        trim(s);
      }
    }
    dirty = true;
  }

  function trim(s) {
    const newest = s.xs[s.xs.length - 1];
    let drop = Math.max(0, s.xs.length - KEEP_POINTS);
    while (drop < s.xs.length && s.xs[drop] < newest - KEEP_SECONDS) drop++;
    if (drop > 1000 || s.xs.length > KEEP_POINTS + 1000) {  // in chunks: splicing is O(n)
      s.xs.splice(0, drop);
      s.ys.splice(0, drop);
    }
  }

  function redraw() {
    frame = visible ? requestAnimationFrame(redraw) : null;
    if (!dirty || !chart || paused) return;
    dirty = false;
    let newest = -Infinity;
    for (const s of series) if (s.xs.length) newest = Math.max(newest, s.xs[s.xs.length - 1]);
    chart.setData([null, ...series.map((s) => [s.xs, s.ys])], false);
    if (follow && newest > -Infinity) {
      const width = Number(windowSelect.value);
      ownScale = true;
      chart.setScale("x", {min: Math.max(0, newest - width), max: Math.max(width, newest)});
      ownScale = false;
    } else {
      chart.redraw();
    }
  }

  app.conn.on("plot_data", onData);
  app.conn.onOpen(() => {  // a new session: ask again for what was plotted
    for (const [plotId, expr] of plots) {
      app.conn.request("plot", {id: plotId, expr}).catch((err) => error.show(err.message));
    }
  });
  app.onGraph((graph) => {
    const list = document.getElementById("plot-topics") || document.body.appendChild(h("datalist", {id: "plot-topics"}));
    fill(list, ...graph.topics.map((t) => h("option", {value: t.name})));
  });
  new ResizeObserver(() => {
    if (!chart) return;
    const box = chartBox.getBoundingClientRect();
    chart.setSize({width: Math.max(200, box.width), height: Math.max(200, box.height || 360)});
  }).observe(chartBox);

  return {
    id: "plot", el,
    show() {
      visible = true;
      dirty = true;
      if (!frame) frame = requestAnimationFrame(redraw);
    },
    hide() {
      visible = false;
    },
    open({expr}) {
      if (expr) add(expr);
    },
    get series() {
      return series.map((s) => ({name: s.name, points: s.xs.length, last: s.ys[s.ys.length - 1]}));
    },
  };
}
