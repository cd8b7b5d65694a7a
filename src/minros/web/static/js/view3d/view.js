// 3D: Rviz in the page. A WebGL scene (three.js) in a fixed frame the user picks, an orbit
// camera (drag: turn, right-drag or shift-drag: pan, wheel: zoom), and displays as Rviz's: Grid,
// TF, RobotModel, Markers, LaserScan, PointCloud2, Map, Path, Pose, PoseArray, Odometry,
// Polygon and InteractiveMarkers; the tools "2D Pose Estimate" and "2D Nav Goal".
//
// The server does the heavy work (minros/web/scene.py): tf lookups into the fixed frame, clouds
// and scans made into arrays sent as binary frames, URDFs parsed, meshes served from their
// packages. Each display has a status line: a display that cannot show its data (an unknown
// frame, a malformed cloud) says so there, and nothing else stops.
//
// The displays and the fixed frame are kept in the browser (localStorage). On a first visit the
// view adds a display for every topic it can show, and a robot model for each robot_description
// parameter, and keeps adding new ones while "add new topics" is ticked.

import {datalist, errorLine, h} from "../ui.js";
import {Scene3D} from "./scene.js";
import {MeshCache} from "./shapes.js";
import {
  CloudDisplay, GridDisplay, KINDS, MapDisplay, MarkersDisplay, OdometryDisplay, PathDisplay,
  PointsDisplay, PolygonDisplay, PoseArrayDisplay, PoseDisplay, RobotDisplay, TFDisplay, TITLES,
} from "./displays.js";
import {Dragger, InteractiveMarkersDisplay} from "./interactive.js";
import {GroundTool, TOOLS} from "./tools.js";

const STORAGE_KEY = "minros.view3d.v1";
const CLASSES = {
  grid3d: GridDisplay, tf: TFDisplay, robot: RobotDisplay, markers: MarkersDisplay,
  scan: PointsDisplay, cloud: CloudDisplay, grid: MapDisplay, path: PathDisplay, pose: PoseDisplay,
  pose_array: PoseArrayDisplay, odometry: OdometryDisplay, polygon: PolygonDisplay,
  imarkers: InteractiveMarkersDisplay,
};
const LOCAL_KINDS = new Set(["grid3d", "tf"]);

/** A fixed frame for a view whose own does not exist: map, odom or world, else the root of the
 * tree with the most frames. */
function pickFixed(frames, current) {
  const names = new Set(frames.map((f) => f.name));
  const known = ["map", "odom", "world"].find((n) => names.has(n) && n !== current);
  if (known) return known;
  const parent = new Map(frames.map((f) => [f.name, f.parent]));
  const size = new Map();
  for (const f of frames) {
    let root = f.name;
    for (let depth = 0; parent.get(root) && depth < 1000; depth++) root = parent.get(root);
    size.set(root, (size.get(root) || 0) + 1);
  }
  const roots = [...size].filter(([name]) => name !== current).sort((a, b) => b[1] - a[1]);
  return roots.length ? roots[0][0] : null;
}

function load() {
  try {
    return JSON.parse(localStorage.getItem(STORAGE_KEY) || "null");
  } catch (err) {
    return null;
  }
}

/** The view, built into `el` (views/view3d.js loads this module when the view is first shown). */
export function createView(app, el) {
  const stage = h("div", {class: "view3d-stage"});
  const fixedInput = h("input", {type: "text", list: "view3d-frames", class: "view3d-fixed",
                                 "aria-label": "fixed frame", title: "the frame the scene is drawn in"});
  const fixedStatus = h("div", {class: "view3d-fixed-status muted"});
  const fpsLabel = h("span", {class: "muted view3d-fps"});
  const noteLine = h("div", {class: "view3d-note muted"});
  const error = errorLine();
  const list = h("div", {class: "view3d-displays"});
  const addSelect = h("select", {class: "view3d-add", "aria-label": "topic to add"});
  const autoAdd = h("input", {type: "checkbox"});
  const toolButtons = {};
  const toolbar = h("div", {class: "toolbar view3d-toolbar"},
    ...[["interact", "Interact", "drag a marker; drag the view to turn, right-drag to pan, wheel to zoom"],
        ...Object.entries(TOOLS).map(([key, spec]) => [key, spec.title, `press where, drag towards the heading: ${spec.type} on ${spec.topic}`])]
      .map(([key, title, tip]) => (toolButtons[key] = h("button", {class: "tool", "data-tool": key, title: tip,
                                                                   onclick: () => view.setTool(key)}, title))),
    h("button", {onclick: () => scene3d.resetCamera(), title: "back to the default view"}, "Reset view"),
    fpsLabel);
  const saved = load();
  const toolInputs = Object.fromEntries(Object.entries(TOOLS).map(([key, spec]) => [key, h("input", {
    type: "text", list: `view3d-tool-${key}`, class: "view3d-tool-topic", "data-tool-topic": key,
    value: (saved && saved.tools && saved.tools[key]) || spec.topic, "aria-label": `${spec.title} topic`,
    title: `${spec.type}: the topic ${spec.title} publishes on`, onchange: () => save()})]));
  const side = h("div", {class: "view3d-side"},
    h("h4", {}, "Global options"),
    h("label", {class: "field-inline"}, "Fixed frame ", fixedInput),
    fixedStatus,
    h("div", {class: "view3d-tools"}, ...Object.entries(TOOLS).map(([key, spec]) =>
      h("label", {class: "field-inline"}, spec.title + " ", toolInputs[key]))),
    h("h4", {}, "Displays"),
    list,
    h("div", {class: "row view3d-add-row"}, addSelect,
      h("button", {onclick: () => addChosen()}, "Add")),
    h("label", {class: "muted"}, autoAdd, " add new topics as they appear"),
    error, noteLine);
  el.replaceChildren(toolbar, h("div", {class: "view3d-layout"}, side, stage));
  const scene3d = new Scene3D(stage);

  const view = {
    app, scene3d, displays: [], tool: "interact", published: [], nextId: 1,
    fixedChosen: Boolean(saved && saved.fixed), removedTopics: new Set(saved ? saved.removed || [] : []),
    meshes: new MeshCache(() => scene3d.invalidate()),
    displaysChanged: () => renderList(),
    /** Ask the server again for a display's data (an option it applies changed). */
    resubscribe: (display) => { if (display.enabled) subscribe(display); },
    setTool(tool) {
      view.tool = tool;
      for (const [key, button] of Object.entries(toolButtons)) button.classList.toggle("active", key === tool);
      scene3d.canvas.style.cursor = tool === "interact" ? "" : "crosshair";
    },
    note(text) {
      noteLine.textContent = text;
    },
    toolTopic(tool) {
      return toolInputs[tool].value.trim() || TOOLS[tool].topic;
    },
  };
  new Dragger(view);
  new GroundTool(view);
  view.setTool("interact");
  autoAdd.checked = saved ? saved.autoAdd !== false : true;
  autoAdd.addEventListener("change", () => { save(); if (autoAdd.checked) autoAddTopics(app.graph); });
  let fixed = (saved && saved.fixed) || "map";
  fixedInput.value = fixed;
  fixedInput.addEventListener("change", () => {
    const name = fixedInput.value.trim().replace(/^\//, "");
    if (name) {
      view.fixedChosen = true;
      setFixed(name);
    }
  });

  // -- the connection --------------------------------------------------------------------

  function watch() {
    app.conn.request("scene_watch", {fixed}).catch((err) => error.show(`scene_watch: ${err.message}`));
  }

  function setFixed(name) {
    fixed = name;
    fixedInput.value = name;
    save();
    if (app.conn.state === "connected") watch();
  }

  app.conn.on("scene_frames", (msg) => {
    if (msg.fixed !== fixed) return;  // an answer to an older choice
    scene3d.setFrames(msg);
    for (const display of view.displays) display.framesChanged();
    const names = msg.frames.map((f) => f.name);
    let datalist = document.getElementById("view3d-frames");
    if (!datalist) document.body.append(datalist = h("datalist", {id: "view3d-frames"}));
    if (datalist.dataset.names !== names.join("\n")) {
      datalist.dataset.names = names.join("\n");
      datalist.replaceChildren(...names.map((n) => h("option", {value: n})));
    }
    // no such frame, nobody chose it, and tf has had 3 s to fill in: pick map, odom or world,
    // else the root of the biggest tree
    if (!msg.error) view.missingSince = 0;
    else if (!view.fixedChosen && !view.missingSince) view.missingSince = performance.now();
    if (msg.error && !view.fixedChosen && performance.now() - view.missingSince > 3000) {
      const pick = pickFixed(msg.frames, fixed);
      if (pick) {
        setFixed(pick);
        return;
      }
    }
    fixedStatus.textContent = msg.error || msg.warning || `${msg.frames.length} frames`;
    fixedStatus.className = "view3d-fixed-status " + (msg.error ? "error" : "muted");
  });
  app.conn.on("scene_data", (msg) => {
    const display = view.displays.find((d) => d.id === msg.id);
    if (display && display.enabled) {
      try {
        display.data(msg);
      } catch (err) {
        display.setLocal("data", "error", `cannot draw the message: ${err.message}`);
        console.warn(err);
      }
    }
  });
  app.conn.on("scene_status", (msg) => {
    const display = view.displays.find((d) => d.id === msg.id);
    if (display) display.setServerStatus(msg.level, msg.text);
  });
  app.conn.onOpen(() => {
    watch();
    for (const display of view.displays) if (display.enabled) subscribe(display);
  });

  function subscribe(display) {
    if (!display.remote || app.conn.state !== "connected") return;
    const fields = display.kind === "robot" ? {kind: "robot", param: display.param}
      : {topic: display.topic, kind: display.kind, ...display.request};  // the kind: for a topic not published yet
    app.conn.request("display_add", {id: display.id, ...fields})
      .catch((err) => display.setServerStatus("error", err.message));
  }

  function unsubscribe(display) {
    if (display.remote) app.conn.send({op: "display_remove", id: display.id});
  }

  // -- displays --------------------------------------------------------------------------

  function addDisplay(config) {
    const Class = CLASSES[config.kind];
    if (!Class) return null;
    const display = new Class(view, {...config, id: `d${view.nextId++}`});
    display.onStatus = () => updateStatus(display);
    view.displays.push(display);
    if (display.enabled) subscribe(display);
    if (config.topic) view.removedTopics.delete(config.topic);
    renderList();
    save();
    return display;
  }

  function removeDisplay(display) {
    unsubscribe(display);
    display.dispose();
    view.displays = view.displays.filter((d) => d !== display);
    if (display.topic || display.kind === "robot") view.removedTopics.add(display.topic || display.param);
    renderList();
    save();
  }

  function setEnabled(display, on) {
    display.setEnabled(on);
    if (on) subscribe(display);
    else {
      unsubscribe(display);
      display.clear();
      display.received = 0;
      display.setServerStatus("", "");
    }
    save();
  }

  function save() {
    try {
      localStorage.setItem(STORAGE_KEY, JSON.stringify({
        fixed: view.fixedChosen ? fixed : undefined, autoAdd: autoAdd.checked,
        tools: Object.fromEntries(Object.entries(toolInputs).map(([key, input]) => [key, input.value.trim()])),
        displays: view.displays.map((d) => d.config()), removed: [...view.removedTopics]}));
    } catch (err) {
      // storage full or disabled: the view works, it is just not remembered
    }
  }

  function updateStatus(display) {
    const row = list.querySelector(`[data-display="${display.id}"]`);
    if (!row) return;
    const {level, text} = display.status;
    const status = row.querySelector(".display-status");
    status.className = "display-status " + (level || "none");
    status.textContent = text;
    row.querySelector(".status-dot").title = {ok: "OK", warn: "warning", error: "error"}[level] || "no data yet";
    row.dataset.level = level || "none";
  }

  const openRows = new Set();

  function renderList() {
    list.replaceChildren(...view.displays.map((display) => {
      const fields = display.constructor.fields.map(([key, title, type, attrs]) => {
        const input = type === "select"
          ? h("select", {"data-option": key}, attrs.options.map((o) => h("option", {value: o}, o)))
          : h("input", {type, ...(attrs || {}), "data-option": key});
        if (type === "checkbox") input.checked = Boolean(display.options[key]);
        else input.value = display.options[key];
        input.addEventListener("change", () => {
          display.setOption(key, type === "checkbox" ? input.checked : type === "number" ? Number(input.value) : input.value);
          save();
        });
        return h("label", {class: "display-option"}, title, " ", input);
      });
      const namespaces = display.namespaces ? [...display.namespaces.keys()].sort().map((ns) => {
        const box = h("input", {type: "checkbox", checked: !display.hiddenNs.has(ns)});
        box.addEventListener("change", () => { display.setNamespace(ns, box.checked); save(); });
        return h("label", {class: "display-option"}, box, " ", ns || "(no namespace)");
      }) : [];
      const enabled = h("input", {type: "checkbox", checked: display.enabled, "aria-label": "shown"});
      enabled.addEventListener("change", () => setEnabled(display, enabled.checked));
      const more = fields.length || namespaces.length ? h("details", {class: "display-more", open: openRows.has(display.id)},
        h("summary", {}, "options"), h("div", {class: "display-options"}, ...fields,
          namespaces.length ? h("div", {class: "muted display-ns"}, "namespaces") : null, ...namespaces)) : null;
      if (more) more.addEventListener("toggle", () => { if (more.open) openRows.add(display.id); else openRows.delete(display.id); });
      const row = h("div", {class: "display-row", "data-display": display.id, "data-kind": display.kind},
        h("div", {class: "display-head"},
          enabled, h("span", {class: "status-dot", title: "status"}), h("b", {}, display.title), h("span", {class: "muted display-source", title: display.source}, display.source),
          h("button", {class: "small remove", title: "remove this display", onclick: () => removeDisplay(display)}, "×")),
        h("div", {class: "display-status"}), more);
      return row;
    }));
    for (const display of view.displays) updateStatus(display);
    renderAddChoices();
  }

  function renderAddChoices() {
    const shown = new Set(view.displays.map((d) => d.topic).filter(Boolean));
    const options = [h("option", {value: ""}, "add a display…")];
    for (const kind of ["grid3d", "tf", "robot"]) {
      if (!view.displays.some((d) => d.kind === kind)) options.push(h("option", {value: "kind:" + kind}, TITLES[kind]));
    }
    for (const topic of app.graph.topics) {
      const kind = KINDS[topic.type];
      if (kind && !shown.has(topic.name)) options.push(h("option", {value: "topic:" + topic.name}, `${topic.name} (${TITLES[kind]})`));
    }
    addSelect.replaceChildren(...options);
  }

  function addChosen() {
    const value = addSelect.value;
    if (value.startsWith("kind:")) addDisplay({kind: value.slice(5)});
    else if (value.startsWith("topic:")) addTopic(value.slice(6));
  }

  function addTopic(topic) {
    const type = app.topicType(topic);
    const kind = KINDS[type];
    if (!kind) {
      error.show(`${topic} is a ${type || "topic of unknown type"}: the 3D view shows ${Object.keys(KINDS).join(", ")}`);
      return null;
    }
    error.show("");
    return addDisplay({kind, topic});
  }

  async function autoAddTopics(graph) {
    if (!autoAdd.checked) return;
    const shown = new Set(view.displays.map((d) => d.topic).filter(Boolean));
    for (const topic of graph.topics) {
      const kind = KINDS[topic.type];
      if (!kind || shown.has(topic.name) || view.removedTopics.has(topic.name) || app.isQuiet(topic.name)) continue;
      // published by someone (not only by this server, as /initialpose after a click)
      if (!topic.publishers || topic.publishers.every((node) => app.isQuiet(node))) continue;
      // a costmap covers the map in strong colours: listed, shown when ticked (as Rviz users
      // add one when they look at planning)
      addDisplay({kind, topic: topic.name, enabled: !(kind === "grid" && /costmap/.test(topic.name))});
    }
    // a robot model for each robot_description parameter (several robots: /tb3_0/..., with
    // the tf_prefix parameter beside it naming their frames' prefix)
    if (robotsSearched) return;
    robotsSearched = true;
    try {
      const {names} = await app.conn.rosapi("get_param_names");
      for (const param of names.filter((n) => n === "/robot_description" || n.endsWith("/robot_description"))) {
        if (view.displays.some((d) => d.kind === "robot" && d.param === param) || view.removedTopics.has(param)) continue;
        const ns = param.slice(0, -"robot_description".length);
        let prefix = "";
        if (ns !== "/") {
          const reply = await app.conn.rosapi("get_param", {name: ns + "tf_prefix", default: "\"\""});
          try {
            prefix = String(JSON.parse(reply.value) || "");
          } catch (err) {
            prefix = "";
          }
        }
        if (!view.displays.some((d) => d.kind === "robot" && d.param === param)) {
          addDisplay({kind: "robot", param, options: {prefix}});
        }
      }
    } catch (err) {
      // rosapi not served: robot models are added by hand
    } finally {
      robotsSearched = false;
    }
  }
  let robotsSearched = false;

  // -- the first displays ----------------------------------------------------------------

  if (saved && Array.isArray(saved.displays)) {
    for (const config of saved.displays) addDisplay(config);
  } else {
    addDisplay({kind: "grid3d"});
    addDisplay({kind: "tf"});
  }

  app.onGraph((graph) => {
    renderAddChoices();
    autoAddTopics(graph);
    // the tools' topics offered: every namespace's (a robot under tb3_0/ has its own)
    for (const [key, spec] of Object.entries(TOOLS)) {
      const names = new Set([spec.topic, ...graph.topics.map((t) => t.name)
        .filter((n) => n.endsWith(spec.topic))]);
      datalist(`view3d-tool-${key}`, [...names].sort());
    }
  });


  // lifetimes, and the frames-per-second line
  scene3d.beforeRender.add((now) => {
    for (const display of view.displays) display.tick(now);
  });
  setInterval(() => {
    if (!scene3d.visible) return;
    const points = view.displays.reduce((n, d) => n + (d.count || 0), 0);
    fpsLabel.textContent = `${scene3d.stats.fps} fps` + (points ? ` · ${points.toLocaleString()} points` : "");
  }, 1000);

  Object.assign(view, {
    id: "3d", el,
    show() {
      scene3d.show();
    },
    hide() {
      scene3d.hide();
    },
    open(args) {
      if (args.fixed) {
        view.fixedChosen = true;
        setFixed(args.fixed);
      }
      if (args.topic) addTopic(args.topic);
    },
    addDisplay, addTopic, removeDisplay, setEnabled, setFixed: (name) => { view.fixedChosen = true; setFixed(name); },
    get fixed() { return fixed; },
    /** What a test reads: each display's kind, source, status and counts. */
    summary() {
      return view.displays.map((d) => ({id: d.id, kind: d.kind, source: d.source, enabled: d.enabled,
                                        received: d.received, count: d.count || 0, total: d.total || 0,
                                        markers: d.markers ? d.markers.size : undefined, ...d.status}));
    },
  });
  return view;
}
