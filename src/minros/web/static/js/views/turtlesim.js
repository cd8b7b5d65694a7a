// turtlesim: the turtles (every turtlesim/Pose topic /<name>/pose) and their pen trails on a
// 500x500 canvas, with turtlesim's own geometry (45 px per metre, y up), and a teleop pad
// that publishes geometry_msgs/Twist on /<name>/cmd_vel like turtle_teleop_key (2.0 m/s,
// 2.0 rad/s) while an arrow is held, on screen or on the keyboard.
//
// turtlesim publishes no pen state, so the page keeps it: the default pen (179,184,255,
// width 3), changed by the pen controls here and by set_pen, clear and reset calls made from
// this page; a set_pen called by another node is not seen.

import {errorLine, h} from "../ui.js";

const METER = 45;
const SIZE = 500;
const DEFAULT_PEN = {r: 179, g: 184, b: 255, width: 3, on: true};
const DEFAULT_BACKGROUND = [69, 86, 255];
const LINEAR = 2.0;
const ANGULAR = 2.0;
const KEYS = {ArrowUp: [1, 0], ArrowDown: [-1, 0], ArrowLeft: [0, 1], ArrowRight: [0, -1]};

function px(x, y) {
  return [x * METER, (SIZE - 1) - y * METER];
}

export function createTurtlesimView(app) {
  const canvas = h("canvas", {width: SIZE, height: SIZE, class: "turtle-canvas", "aria-label": "turtlesim"});
  const ctx = canvas.getContext("2d");
  const trails = h("canvas", {width: SIZE, height: SIZE});
  const tctx = trails.getContext("2d");
  const select = h("select", {onchange: () => { selected = select.value; syncPenControls(); }});
  const penColor = h("input", {type: "color", value: "#b3b8ff"});
  const penWidth = h("input", {type: "number", min: 1, max: 20, value: 3, class: "narrow"});
  const penOn = h("input", {type: "checkbox", checked: true});
  const error = errorLine();
  const status = h("div", {class: "muted"});
  const pad = h("div", {class: "teleop"},
    padButton("▲", "ArrowUp", "forward"), padButton("◀", "ArrowLeft", "turn left"),
    padButton("■", null, "stop"), padButton("▶", "ArrowRight", "turn right"), padButton("▼", "ArrowDown", "backward"));
  const el = h("section", {},
    h("div", {class: "turtle-layout"},
      h("div", {class: "turtle-stage"}, canvas),
      h("div", {class: "turtle-side"},
        h("h3", {}, "Teleop"),
        h("label", {}, "turtle ", select),
        pad,
        h("p", {class: "muted"}, "Hold an arrow (here or on the keyboard) to drive; the turtle stops 1 s after the last command."),
        h("h3", {}, "Pen"),
        h("div", {class: "row"}, penColor, h("label", {}, "width ", penWidth), h("label", {}, penOn, " on"),
          h("button", {onclick: () => setPen()}, "Set pen")),
        h("h3", {}, "turtlesim"),
        h("div", {class: "row"}, h("button", {onclick: () => spawn()}, "Spawn"),
          h("button", {onclick: () => call("/clear")}, "Clear"), h("button", {onclick: () => call("/reset")}, "Reset")),
        error, status)));

  const turtles = new Map();  // name -> {pose, last, pen, unsubscribe}
  let selected = "";
  let background = DEFAULT_BACKGROUND;
  let visible = false;
  let dirty = true;
  let frame = null;
  let held = new Set();
  let driveTimer = null;
  let node = "/turtlesim";

  function padButton(label, key, title) {
    const button = h("button", {class: "pad-" + (key || "stop"), title, "aria-label": title});
    button.textContent = label;
    if (!key) {
      button.addEventListener("click", () => { held.clear(); drive(); });
      return button;
    }
    const press = (event) => { event.preventDefault(); held.add(key); button.classList.add("active"); startDriving(); };
    const release = () => { held.delete(key); button.classList.remove("active"); };
    button.addEventListener("pointerdown", press);
    button.addEventListener("pointerup", release);
    button.addEventListener("pointerleave", release);
    button.addEventListener("pointercancel", release);
    return button;
  }

  function clearTrails() {
    tctx.fillStyle = `rgb(${background.join(",")})`;
    tctx.fillRect(0, 0, SIZE, SIZE);
    for (const turtle of turtles.values()) turtle.last = null;
    dirty = true;
  }

  async function readBackground() {
    const values = [];
    for (const [i, c] of ["r", "g", "b"].entries()) {
      try {
        const reply = await app.conn.rosapi("get_param", {name: `${node}/background_${c}`, default: String(DEFAULT_BACKGROUND[i])});
        const v = JSON.parse(reply.value);
        values.push(Number.isInteger(v) ? v & 255 : DEFAULT_BACKGROUND[i]);
      } catch (err) {
        values.push(DEFAULT_BACKGROUND[i]);
      }
    }
    background = values;
  }

  function onPose(name, pose) {
    const turtle = turtles.get(name);
    if (!turtle) return;
    const point = px(pose.x, pose.y);
    if (turtle.last && turtle.pen.on && (turtle.last[0] !== point[0] || turtle.last[1] !== point[1])) {
      tctx.strokeStyle = `rgb(${turtle.pen.r},${turtle.pen.g},${turtle.pen.b})`;
      tctx.lineWidth = turtle.pen.width;
      tctx.lineCap = "round";
      tctx.beginPath();
      tctx.moveTo(...turtle.last);
      tctx.lineTo(...point);
      tctx.stroke();
    }
    turtle.last = point;
    turtle.pose = pose;
    dirty = true;
  }

  function sync(graph) {
    const found = new Map();
    for (const topic of graph.topics) {
      if (topic.type === "turtlesim/Pose" && topic.name.endsWith("/pose") && topic.publishers.length) {
        found.set(topic.name.slice(1, -"/pose".length), topic.publishers[0]);
      }
    }
    for (const [name, turtle] of turtles) {
      if (!found.has(name)) {
        turtle.unsubscribe();
        turtles.delete(name);
        dirty = true;
      }
    }
    for (const [name, publisher] of found) {
      if (turtles.has(name)) continue;
      node = publisher;
      const turtle = {pose: null, last: null, pen: {...DEFAULT_PEN}, unsubscribe: null};
      turtles.set(name, turtle);
      turtle.unsubscribe = app.conn.subscribe(`/${name}/pose`, "turtlesim/Pose", (pose) => onPose(name, pose));
    }
    const names = [...turtles.keys()].sort();
    if (!names.includes(selected)) selected = names[0] || "";
    select.replaceChildren(...names.map((n) => h("option", {value: n, selected: n === selected}, n)));
    status.textContent = names.length ? `${names.length} turtle${names.length > 1 ? "s" : ""} (${node})` : "No turtlesim running: rosrun turtlesim turtlesim_node";
    syncPenControls();
  }

  function syncPenControls() {
    const turtle = turtles.get(selected);
    if (!turtle) return;
    const {r, g, b, width, on} = turtle.pen;
    penColor.value = "#" + [r, g, b].map((v) => v.toString(16).padStart(2, "0")).join("");
    penWidth.value = width;
    penOn.checked = on;
  }

  /** A turtle seen from above, about turtlesim's 45 px, heading along +x before rotation. */
  function drawTurtle(name, pose, isSelected) {
    const [x, y] = px(pose.x, pose.y);
    const blob = (cx, cy, rx, ry) => {
      ctx.beginPath();
      ctx.ellipse(cx, cy, rx, ry, 0, 0, Math.PI * 2);
      ctx.fill();
      ctx.stroke();
    };
    ctx.save();
    ctx.translate(x, y);
    ctx.rotate(-pose.theta);
    ctx.lineWidth = 1.5;
    ctx.strokeStyle = "#1b4d18";
    ctx.fillStyle = "#6aa84f";
    for (const [lx, ly] of [[9, 13], [9, -13], [-9, 13], [-9, -13]]) blob(lx, ly, 5, 4);  // legs
    blob(-18, 0, 4, 2.5);  // tail
    blob(20, 0, 7, 6);     // head
    ctx.fillStyle = "#8d6e3f";
    ctx.strokeStyle = isSelected ? "#ffeb3b" : "#3e2b12";
    ctx.lineWidth = isSelected ? 3 : 1.5;
    blob(0, 0, 16, 13);    // shell
    ctx.strokeStyle = "#5b4322";
    ctx.lineWidth = 1;
    ctx.beginPath();       // shell pattern
    ctx.moveTo(-9, 0);
    ctx.lineTo(9, 0);
    ctx.moveTo(-5, -9);
    ctx.lineTo(-5, 9);
    ctx.moveTo(5, -9);
    ctx.lineTo(5, 9);
    ctx.stroke();
    ctx.restore();
    ctx.fillStyle = "#fff";
    ctx.font = "12px system-ui, sans-serif";
    ctx.fillText(name, x + 18, y - 18);
  }

  function render() {
    frame = visible ? requestAnimationFrame(render) : null;
    if (!dirty) return;
    dirty = false;
    ctx.drawImage(trails, 0, 0);
    for (const [name, turtle] of turtles) if (turtle.pose) drawTurtle(name, turtle.pose, name === selected);
  }

  function twist() {
    let forward = 0;
    let turn = 0;
    for (const key of held) {
      forward += KEYS[key][0];
      turn += KEYS[key][1];
    }
    return {linear: {x: LINEAR * forward, y: 0, z: 0}, angular: {x: 0, y: 0, z: ANGULAR * turn}};
  }

  function drive() {
    if (!selected) return;
    app.conn.publish(`/${selected}/cmd_vel`, "geometry_msgs/Twist", twist());
  }

  function startDriving() {
    drive();
    if (driveTimer) return;
    driveTimer = setInterval(() => {
      if (!held.size) {
        clearInterval(driveTimer);
        driveTimer = null;
        drive();  // one stop command, as when teleop_key's key is released
        return;
      }
      drive();
    }, 100);
  }

  function keyEvent(event, down) {
    if (!visible || !(event.key in KEYS)) return;
    if (event.target.closest && event.target.closest("input, textarea, select")) return;
    event.preventDefault();
    if (down) {
      held.add(event.key);
      startDriving();
    } else {
      held.delete(event.key);
    }
  }
  window.addEventListener("keydown", (event) => keyEvent(event, true));
  window.addEventListener("keyup", (event) => keyEvent(event, false));

  async function call(service, args = {}) {
    error.show("");
    try {
      return await app.conn.callService(service, args);
    } catch (err) {
      error.show(`${service}: ${err.message}`);
      return null;
    }
  }

  function setPen() {
    if (!selected) return;
    const hex = penColor.value;
    const [r, g, b] = [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16));
    call(`/${selected}/set_pen`, {r, g, b, width: Number(penWidth.value) || 1, off: penOn.checked ? 0 : 1});
  }

  function spawn() {
    const rand = (lo, hi) => lo + Math.random() * (hi - lo);
    call("/spawn", {x: rand(1, 10), y: rand(1, 10), theta: rand(-3.14, 3.14), name: ""});
  }

  // what this page's service calls do to the picture (turtlesim publishes no pen state)
  app.conn.on("service_called", ({service, args}) => {
    const name = service.replace(/^\//, "");
    if (name.endsWith("/set_pen")) {
      const turtle = turtles.get(name.slice(0, -"/set_pen".length));
      if (turtle) {
        turtle.pen = {r: args.r ?? 0, g: args.g ?? 0, b: args.b ?? 0, width: args.width || 1, on: !args.off};
        syncPenControls();
      }
    } else if (service === "/clear" || service === `${node}/clear`) {
      readBackground().then(clearTrails);
    } else if (service === "/reset" || service === `${node}/reset`) {
      for (const turtle of turtles.values()) turtle.pen = {...DEFAULT_PEN};
      readBackground().then(clearTrails);
      syncPenControls();
    }
  });

  app.onGraph(sync);
  app.conn.onOpen(() => readBackground().then(clearTrails));
  clearTrails();

  return {
    id: "turtlesim", el,
    show() {
      visible = true;
      dirty = true;
      if (!frame) frame = requestAnimationFrame(render);
    },
    hide() {
      visible = false;
      held.clear();
    },
    get turtles() {
      return [...turtles].map(([name, t]) => ({name, pose: t.pose, pen: t.pen}));
    },
  };
}
