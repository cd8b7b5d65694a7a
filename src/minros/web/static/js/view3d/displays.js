// The 3D view's displays, as Rviz's: each draws one source (a topic, tf, the robot model, the
// ground grid) into its own group of the scene, with options and a status.
//
// A display gets the server's scene_data frames for its id (`data(msg)`), is told when tf moved
// (`framesChanged()`), and reports its status: the server's (a frame tf does not know, a
// malformed message) or its own (a link without tf, a mesh that did not load); the worst wins.

import * as THREE from "three";
import {ARROW, MeshCache, arrow, axes, buildMarker, dispose, label, lines, material} from "./shapes.js";
import {poseMatrix, setPose} from "./scene.js";

const LEVELS = {"": 0, ok: 1, warn: 2, error: 3};

/** The kind of display for each message type the view shows (the server's KINDS). */
export const KINDS = {
  "visualization_msgs/Marker": "markers",
  "visualization_msgs/MarkerArray": "markers",
  "sensor_msgs/LaserScan": "scan",
  "sensor_msgs/PointCloud2": "cloud",
  "nav_msgs/OccupancyGrid": "grid",
  "nav_msgs/Path": "path",
  "geometry_msgs/PoseStamped": "pose",
  "geometry_msgs/PoseWithCovarianceStamped": "pose",
  "geometry_msgs/PoseArray": "pose_array",
  "nav_msgs/Odometry": "odometry",
  "geometry_msgs/PolygonStamped": "polygon",
  "visualization_msgs/InteractiveMarkerUpdate": "imarkers",
};

export const TITLES = {
  grid3d: "Grid", tf: "TF", robot: "RobotModel", markers: "Markers", scan: "LaserScan",
  cloud: "PointCloud2", grid: "Map", path: "Path", pose: "Pose", pose_array: "PoseArray",
  odometry: "Odometry", polygon: "Polygon", imarkers: "InteractiveMarkers",
};

function hexColor(hex) {
  const n = parseInt(hex.slice(1), 16);
  return [(n >> 16 & 255) / 255, (n >> 8 & 255) / 255, (n & 255) / 255, 1];
}

export class Display {
  /** config: {id, kind, topic?, param?, enabled, options} */
  constructor(view, config) {
    this.view = view;
    this.scene = view.scene3d;
    this.id = config.id;
    this.kind = config.kind;
    this.topic = config.topic || "";
    this.param = config.param || "";
    this.enabled = config.enabled !== false;
    this.options = {...this.constructor.defaults, ...(config.options || {})};
    this.group = new THREE.Group();
    this.group.name = `display ${this.id}`;
    this.group.visible = this.enabled;
    this.scene.scene.add(this.group);
    this.serverStatus = {level: "", text: ""};
    this.local = new Map();  // key -> {level, text}
    this.received = 0;
    this.onStatus = () => {};
  }

  static defaults = {};
  /** [key, label, type ("color", "number", "checkbox"), extra input attributes] */
  static fields = [];
  /** Whether the server sends this display data (display_add). */
  get remote() { return true; }
  /** What display_add asks the server for besides the topic (a cloud's max_points). */
  get request() { return {}; }

  get title() { return TITLES[this.kind] || this.kind; }
  get source() { return this.topic || this.param; }

  config() {
    return {kind: this.kind, topic: this.topic || undefined, param: this.param || undefined,
            enabled: this.enabled, options: this.options};
  }

  setServerStatus(level, text) {
    this.serverStatus = {level, text};
    this.onStatus();
  }

  setLocal(key, level, text) {
    const was = this.local.get(key);
    if (was ? was.level === level && was.text === text : !level) return;  // as it is (data at 10 Hz)
    if (level) this.local.set(key, {level, text});
    else this.local.delete(key);
    this.onStatus();
  }

  get status() {
    let worst = this.serverStatus;
    for (const s of this.local.values()) {
      // the worst level; at the same level, a text rather than none ("ok" with a note)
      if (LEVELS[s.level] > LEVELS[worst.level] || (s.level === worst.level && !worst.text)) worst = s;
    }
    if (!worst.level && !this.remote) return {level: "ok", text: ""};
    if (!worst.level && !this.received) return {level: "", text: "waiting for messages"};
    return worst;
  }

  setEnabled(on) {
    this.enabled = on;
    this.group.visible = on;
    this.scene.invalidate();
  }

  setOption(key, value) {
    this.options[key] = value;
    this.applyOptions();
    this.scene.invalidate();
  }

  applyOptions() {}
  data(_msg) {}
  framesChanged() {}
  tick(_now) {}

  clear() {
    for (const child of [...this.group.children]) dispose(child);
    this.scene.invalidate();
  }

  dispose() {
    dispose(this.group);
    this.scene.invalidate();
  }
}

// -- local displays ------------------------------------------------------------------------

export class GridDisplay extends Display {
  static defaults = {cells: 10, size: 1, color: "#a0a0a4"};
  static fields = [["cells", "cells", "number", {min: 1, max: 1000, step: 1}],
                   ["size", "cell size (m)", "number", {min: 0.01, step: 0.1}], ["color", "color", "color"]];
  get remote() { return false; }

  constructor(view, config) {
    super(view, config);
    this.scene.grid.visible = false;  // this display draws the grid
    this.applyOptions();
  }

  applyOptions() {
    this.clear();
    const cells = Math.max(1, Math.round(this.options.cells));
    const size = Math.max(0.001, Number(this.options.size));
    const grid = new THREE.GridHelper(cells * size, cells, this.options.color, this.options.color);
    grid.rotation.x = Math.PI / 2;
    this.group.add(grid);
  }
}

export class TFDisplay extends Display {
  static defaults = {names: true, axes: true, arrows: true, scale: 1};
  static fields = [["names", "names", "checkbox"], ["axes", "axes", "checkbox"],
                   ["arrows", "parent arrows", "checkbox"], ["scale", "scale", "number", {min: 0.05, step: 0.1}]];
  get remote() { return false; }

  constructor(view, config) {
    super(view, config);
    this.items = new Map();  // frame -> {group, axes, label, stale}
    this.links = null;
  }

  applyOptions() {
    for (const item of this.items.values()) dispose(item.group);
    this.items.clear();
    this.framesChanged();
  }

  framesChanged() {
    const frames = this.scene.frames;
    const scale = Number(this.options.scale) || 1;
    for (const [name, item] of this.items) {
      if (!frames.has(name)) {
        dispose(item.group);
        this.items.delete(name);
      }
    }
    const positions = [];
    for (const [name, f] of frames) {
      let item = this.items.get(name);
      if (!item) {
        const group = new THREE.Group();
        group.matrixAutoUpdate = false;
        group.name = name;
        item = {group, stale: null};
        if (this.options.axes) group.add(item.axes = axes(0.3 * scale, 0.008 * scale));
        if (this.options.names) {
          item.label = label(name, 0.08 * scale);
          item.label.position.set(0, 0, 0.06 * scale);
          item.label.center.set(0, 0);
          group.add(item.label);
        }
        this.group.add(group);
        this.items.set(name, item);
      }
      item.group.visible = Boolean(f.matrix);
      if (f.matrix) {
        item.group.matrix.copy(f.matrix);
        item.group.matrixWorldNeedsUpdate = true;
      }
      if (item.stale !== f.stale) {  // a frame nobody refreshes fades, as in Rviz
        item.stale = f.stale;
        item.group.traverse((o) => {
          if (!o.material) return;
          o.material.transparent = true;
          o.material.opacity = f.stale ? 0.25 : 1;
        });
      }
      const parent = f.parent && frames.get(f.parent);
      if (this.options.arrows && f.matrix && parent && parent.matrix) {
        const a = new THREE.Vector3().setFromMatrixPosition(f.matrix);
        const b = new THREE.Vector3().setFromMatrixPosition(parent.matrix);
        positions.push(a.x, a.y, a.z, b.x, b.y, b.z);
      }
    }
    if (this.links) dispose(this.links);
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.Float32BufferAttribute(positions, 3));
    this.links = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({color: 0xe0d040}));
    this.group.add(this.links);
    const stale = [...frames.values()].filter((f) => f.stale).map((f) => f.name);
    this.setLocal("stale", stale.length ? "warn" : "",
                  `${stale.length} frame${stale.length > 1 ? "s" : ""} not updated for 5 s: ${stale.slice(0, 4).join(", ")}`);
  }
}

// -- the robot model -----------------------------------------------------------------------

export class RobotDisplay extends Display {
  static defaults = {alpha: 1, color: "#cccccc", prefix: ""};
  static fields = [["alpha", "alpha", "number", {min: 0, max: 1, step: 0.1}],
                   ["prefix", "tf prefix", "text", {size: 10}]];

  constructor(view, config) {
    super(view, config);
    this.param = this.param || "/robot_description";
    this.links = new Map();   // link name -> anchor
    this.meshes = new MeshCache(() => this.scene.invalidate());
    this.robot = null;
  }

  get title() { return "RobotModel"; }

  /** The tf frame of a link: Rviz's "TF Prefix" before its name. */
  frame(link) {
    const prefix = String(this.options.prefix || "").replace(/^\/+|\/+$/g, "");
    return prefix ? `${prefix}/${link}` : link;
  }

  data(msg) {
    this.received++;
    this.last = msg;
    this.drawnPrefix = this.options.prefix;
    this.clear();
    this.links.clear();
    this.local.clear();
    this.onStatus();
    this.robot = msg.robot;
    const problems = [];
    for (const link of msg.robot.links) {
      const anchor = this.scene.anchor({frame: this.frame(link.name), locked: true}, this.group);
      anchor.name = link.name;
      for (const visual of link.visuals) {
        const color = visual.color || hexColor(this.options.color);
        const holder = new THREE.Group();
        setPose(holder, visual.origin);
        const g = visual.geometry;
        if (g.type === "box") {
          const mesh = new THREE.Mesh(new THREE.BoxGeometry(...g.size), material(color));
          holder.add(mesh);
        } else if (g.type === "cylinder") {
          const mesh = new THREE.Mesh(new THREE.CylinderGeometry(g.radius, g.radius, g.length, 24)
            .rotateX(Math.PI / 2), material(color));
          holder.add(mesh);
        } else if (g.type === "sphere") {
          holder.add(new THREE.Mesh(new THREE.SphereGeometry(g.radius, 24, 16), material(color)));
        } else if (g.type === "mesh") {
          const scaled = new THREE.Group();
          scaled.scale.set(...g.scale);
          holder.add(scaled);
          this.meshes.add(scaled, g.url, visual.color || null, !visual.color, (url, text) => {
            problems.push(`${g.uri}: ${text}`);
            this.setLocal("meshes", "error", `cannot load ${problems.join("; ")}`);
          });
        }
        anchor.add(holder);
      }
      this.links.set(link.name, anchor);
    }
    this.applyOptions();
    this.framesChanged();
  }

  applyOptions() {
    if (this.last && this.drawnPrefix !== this.options.prefix) {
      this.data(this.last);  // calls applyOptions again, with the new frames
      return;
    }
    const alpha = Number(this.options.alpha);
    this.group.traverse((o) => {
      if (!o.isMesh) return;
      const mats = Array.isArray(o.material) ? o.material : [o.material];
      for (const m of mats) {
        if (m.userData.shared) continue;
        m.transparent = alpha < 1;
        m.opacity = alpha;
        m.depthWrite = alpha >= 1;
      }
    });
  }

  framesChanged() {
    if (!this.robot) return;
    const missing = [...this.links].filter(([, anchor]) => !anchor.visible).map(([name]) => this.frame(name));
    this.setLocal("tf", missing.length ? "warn" : "",
                  `No transform from [${missing.slice(0, 3).join("], [")}]${missing.length > 3 ? ` and ${missing.length - 3} more` : ""} to [${this.scene.fixed}]`);
  }
}

// -- markers -------------------------------------------------------------------------------

export class MarkersDisplay extends Display {
  constructor(view, config) {
    super(view, config);
    this.markers = new Map();     // "ns\0id" -> {anchor, expires}
    this.namespaces = new Map();  // ns -> {group, count}
    this.meshes = new MeshCache(() => this.scene.invalidate());
    this.hiddenNs = new Set(this.options.hidden || []);
  }

  static defaults = {hidden: []};

  nsGroup(ns) {
    let entry = this.namespaces.get(ns);
    if (!entry) {
      const group = new THREE.Group();
      group.visible = !this.hiddenNs.has(ns);
      this.group.add(group);
      entry = {group, count: 0};
      this.namespaces.set(ns, entry);
      this.view.displaysChanged();
    }
    return entry;
  }

  setNamespace(ns, visible) {
    if (visible) this.hiddenNs.delete(ns);
    else this.hiddenNs.add(ns);
    this.options.hidden = [...this.hiddenNs];
    const entry = this.namespaces.get(ns);
    if (entry) entry.group.visible = visible;
    this.scene.invalidate();
  }

  remove(key) {
    const found = this.markers.get(key);
    if (!found) return;
    dispose(found.anchor);
    this.markers.delete(key);
    this.namespaces.get(found.ns).count--;
  }

  data(msg) {
    this.received++;
    const now = performance.now();
    for (const m of msg.markers) {
      const key = `${m.ns}\u0000${m.id}`;
      if (m.action === 3) {  // DELETEALL
        for (const k of [...this.markers.keys()]) this.remove(k);
        continue;
      }
      this.remove(key);
      if (m.action === 2) continue;  // DELETE
      const ns = this.nsGroup(m.ns);
      const anchor = this.scene.anchor({frame: m.frame, T: m.T, fixed: msg.fixed, locked: m.locked}, ns.group);
      anchor.add(buildMarker(m, this.meshes));
      ns.count++;
      this.markers.set(key, {anchor, ns: m.ns, expires: m.lifetime > 0 ? now + m.lifetime * 1000 : 0,
                             type: m.type});
    }
    this.scene.invalidate();
  }

  tick(now) {
    let removed = false;
    for (const [key, m] of this.markers) {
      if (m.expires && now >= m.expires) {
        this.remove(key);
        removed = true;
      }
    }
    if (removed) this.scene.invalidate();
  }

  clear() {
    for (const k of [...this.markers.keys()]) this.remove(k);
  }
}

// -- point clouds and scans ----------------------------------------------------------------

/** Points a software renderer draws of a big cloud while the camera moves: every STRIDE-th
 * (the whole cloud again as soon as the camera stops). */
const STRIDE = 4;
const COARSE_FROM = 50000;

export class PointsDisplay extends Display {
  static defaults = {size: 0.02, color: "#ff0000", alpha: 1};
  static fields = [["size", "size (m)", "number", {min: 0.001, step: 0.01}], ["color", "flat color", "color"],
                   ["alpha", "alpha", "number", {min: 0, max: 1, step: 0.1}]];

  constructor(view, config) {
    super(view, config);
    if (this.kind === "scan" && !config.options) this.options.size = 0.05;
    this.capacity = 0;
    this.geometry = new THREE.BufferGeometry();
    this.material = new THREE.PointsMaterial({size: this.options.size, sizeAttenuation: true});
    this.points = new THREE.Points(this.geometry, this.material);
    this.points.frustumCulled = false;  // the bounds change with every message
    // the same arrays through an index of every STRIDE-th point, drawn instead of the whole
    // cloud while the camera moves on a software renderer (vertices are what it is slow at)
    this.coarseGeometry = new THREE.BufferGeometry();
    this.coarse = new THREE.Points(this.coarseGeometry, this.material);
    this.coarse.frustumCulled = false;
    this.coarse.visible = false;
    this.anchor = null;
    this.count = 0;
    this.applyOptions();
  }

  tick() {
    const coarse = this.scene.software && this.scene.moving && this.count >= COARSE_FROM;
    if (coarse !== this.coarse.visible) {
      this.coarse.visible = coarse;
      this.points.visible = !coarse;
    }
  }

  applyOptions() {
    this.material.size = Number(this.options.size) || 0.02;
    // a colored cloud's colors are its points' own (white multiplies them): the flat color is
    // for clouds without colors, also when another option (max points, size) changes
    this.material.color.setRGB(...(this.material.vertexColors
      ? [1, 1, 1] : hexColor(this.options.color).slice(0, 3)));
    const alpha = Number(this.options.alpha);
    this.material.transparent = alpha < 1;
    this.material.opacity = alpha;
    this.material.needsUpdate = true;
  }

  data(msg) {
    this.received++;
    const {position, color} = msg.arrays;
    const count = msg.count;
    if (count > this.capacity) {  // grow (by half again) and upload whole
      this.capacity = Math.ceil(count * 1.5);
      this.geometry.dispose();
      this.geometry = new THREE.BufferGeometry();
      const pos = new THREE.BufferAttribute(new Float32Array(this.capacity * 3), 3);
      pos.setUsage(THREE.DynamicDrawUsage);
      const col = new THREE.BufferAttribute(new Uint8Array(this.capacity * 3), 3, true);
      col.setUsage(THREE.DynamicDrawUsage);
      this.geometry.setAttribute("position", pos);
      this.geometry.setAttribute("color", col);
      this.points.geometry = this.geometry;
      this.coarseGeometry.dispose();
      this.coarseGeometry = new THREE.BufferGeometry();
      this.coarseGeometry.setAttribute("position", pos);
      this.coarseGeometry.setAttribute("color", col);
      const index = new Uint32Array(Math.ceil(this.capacity / STRIDE));
      for (let i = 0; i < index.length; i++) index[i] = i * STRIDE;
      this.coarseGeometry.setIndex(new THREE.BufferAttribute(index, 1));
      this.coarse.geometry = this.coarseGeometry;
    }
    const pos = this.geometry.getAttribute("position");
    pos.array.set(position);
    pos.clearUpdateRanges();
    pos.addUpdateRange(0, count * 3);
    pos.needsUpdate = true;
    const colored = Boolean(color);
    if (colored) {
      const col = this.geometry.getAttribute("color");
      col.array.set(color);
      col.clearUpdateRanges();
      col.addUpdateRange(0, count * 3);
      col.needsUpdate = true;
    }
    if (this.material.vertexColors !== colored) {
      this.material.vertexColors = colored;
      this.material.color.setRGB(...(colored ? [1, 1, 1] : hexColor(this.options.color).slice(0, 3)));
      this.material.needsUpdate = true;
    }
    this.geometry.setDrawRange(0, count);
    this.coarseGeometry.setDrawRange(0, Math.ceil(count / STRIDE));
    this.count = count;
    this.total = msg.total ?? count;
    const place = {frame: msg.frame, T: msg.T, fixed: msg.fixed};
    if (!this.anchor) {
      this.anchor = this.scene.anchor(place, this.group);
      this.anchor.add(this.points, this.coarse);
    } else {
      this.anchor.userData.place = place;
      this.scene.placeAnchor(this.anchor);
    }
    this.scene.invalidate();
  }
}

/** The points of a cloud a software renderer draws by default: SwiftShader spends about
 * 0.7 us of CPU on each point it draws, so a 100,000-point cloud costs ~70 ms a frame and
 * 25,000 points ~17 ms (measured in tests/integration/test_page_3d.py). */
export const SOFTWARE_MAX_POINTS = 25000;

export class CloudDisplay extends PointsDisplay {
  static fields = [...PointsDisplay.fields,
                   ["max_points", "max points (0: all)", "number", {min: 0, step: 5000}]];

  constructor(view, config) {
    super(view, config);
    // the server sends at most this many points of each cloud, spread over it: on a GPU all of
    // them, on a software renderer as many as it draws smoothly (see SOFTWARE_MAX_POINTS)
    if (!(config.options && "max_points" in config.options)) {
      this.options.max_points = this.scene.software ? SOFTWARE_MAX_POINTS : 0;
    }
  }

  /** What display_add asks the server for. */
  get request() {
    return {max_points: Math.max(0, Math.round(Number(this.options.max_points) || 0))};
  }

  setOption(key, value) {
    super.setOption(key, value);
    if (key === "max_points") this.view.resubscribe(this);
  }

  data(msg) {
    super.data(msg);
    const max = this.request.max_points;
    this.setLocal("thinned", max && this.total > max ? "ok" : "",
                  `${this.count.toLocaleString("en")} of ${this.total.toLocaleString("en")} points shown (max points)`);
  }
}

// -- maps ----------------------------------------------------------------------------------

/** Rviz's colour schemes of a grid, packed RGBA as uint32 (little endian, as typed arrays are
 * on every browser's machine). "map": 0..100 white to black; "costmap": 0 clear, 1..98 blue to
 * red, 99 (inscribed) cyan, 100 (lethal) purple. Both: -1 (255 here) a grey green, other
 * values (illegal) green above 100 and red to yellow below 0. */
function palette(scheme) {
  const out = new Uint32Array(256);
  const rgba = (r, g, b, a) => (a << 24 | b << 16 | g << 8 | r) >>> 0;
  if (scheme === "costmap") {
    out[0] = rgba(0, 0, 0, 0);
    for (let i = 1; i <= 98; i++) {
      const v = Math.floor(255 * i / 100);
      out[i] = rgba(v, 0, 255 - v, 255);
    }
    out[99] = rgba(0, 255, 255, 255);
    out[100] = rgba(255, 0, 255, 255);
  } else {
    for (let i = 0; i <= 100; i++) {
      const v = 255 - Math.floor(255 * i / 100);
      out[i] = rgba(v, v, v, 255);
    }
  }
  for (let i = 101; i <= 127; i++) out[i] = rgba(0, 255, 0, 255);
  for (let i = 128; i <= 254; i++) out[i] = rgba(255, Math.floor(255 * (i - 128) / (254 - 128)), 0, 255);
  out[255] = rgba(0x70, 0x89, 0x86, 255);
  return out;
}
const PALETTES = {map: palette("map"), costmap: palette("costmap")};

const MAP_VERTEX = `varying vec2 vUv;
void main() {
  vUv = uv;
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}`;
const MAP_FRAGMENT = `uniform sampler2D map;
uniform float opacity;
varying vec2 vUv;
void main() {
  vec4 texel = texture2D(map, vUv);
  gl_FragColor = vec4(texel.rgb, texel.a * opacity);
}`;

export class MapDisplay extends Display {
  static defaults = {alpha: 0.7, scheme: "map"};
  static fields = [["alpha", "alpha", "number", {min: 0, max: 1, step: 0.1}],
                   ["scheme", "colours", "select", {options: ["map", "costmap"]}]];

  constructor(view, config) {
    super(view, config);
    // move_base's costmaps get Rviz's costmap colours unless chosen otherwise
    if (!(config.options && config.options.scheme) && /costmap/.test(this.topic)) this.options.scheme = "costmap";
  }

  data(msg) {
    this.received++;
    const {width, height, resolution, origin} = msg;
    const cells = msg.arrays.cells;
    this.last = msg;
    msg.scheme = this.options.scheme;  // what it was drawn with (applyOptions redraws on a change)
    const colours = PALETTES[this.options.scheme] || PALETTES.map;
    const pixels = new Uint32Array(width * height);
    for (let i = 0; i < cells.length; i++) pixels[i] = colours[cells[i]];
    const rgba = new Uint8Array(pixels.buffer);
    if (!this.mesh || this.size !== `${width}x${height}x${resolution}`) {
      this.clear();
      this.size = `${width}x${height}x${resolution}`;
      // one cell, one texel, no filtering (as Rviz draws a map); the palette's sRGB bytes are
      // what the screen shows, so the shader hands them on (no sRGB decode per texel and
      // encode per pixel): a map covers much of the view, and every pixel of it costs a
      // software renderer (a third of a frame with the standard material, a tenth with this)
      const texture = new THREE.DataTexture(rgba, width, height, THREE.RGBAFormat);
      texture.magFilter = THREE.NearestFilter;
      texture.minFilter = THREE.NearestFilter;
      texture.needsUpdate = true;
      const mat = new THREE.ShaderMaterial({
        uniforms: {map: {value: texture}, opacity: {value: 1}},
        vertexShader: MAP_VERTEX, fragmentShader: MAP_FRAGMENT, side: THREE.DoubleSide,
        transparent: true, depthWrite: false, polygonOffset: true, polygonOffsetFactor: 1,
        polygonOffsetUnits: 1});
      this.mesh = new THREE.Mesh(new THREE.PlaneGeometry(width * resolution, height * resolution), mat);
      this.mesh.position.set(width * resolution / 2, height * resolution / 2, 0);
      this.origin = new THREE.Group();
      this.origin.add(this.mesh);
      this.anchor = this.scene.anchor({frame: msg.frame, locked: true}, this.group);
      this.anchor.add(this.origin);
    } else {
      const texture = this.mesh.material.uniforms.map.value;
      texture.image.data = rgba;
      texture.needsUpdate = true;
      this.anchor.userData.place = {frame: msg.frame, locked: true};
      this.scene.placeAnchor(this.anchor);
    }
    setPose(this.origin, origin);
    this.applyOptions();
    this.scene.invalidate();
  }

  applyOptions() {
    if (this.mesh) this.mesh.material.uniforms.opacity.value = Number(this.options.alpha);
    if (this.last && this.last.scheme !== this.options.scheme) this.data(this.last);
  }

  clear() {
    super.clear();
    this.mesh = null;
  }
}

// -- paths, poses, polygons, odometry ------------------------------------------------------

class StampedDisplay extends Display {
  /** Replace what is drawn with `object` at the message's frame and stamp. */
  show(msg, object) {
    this.received++;
    this.clear();
    const anchor = this.scene.anchor({frame: msg.frame, T: msg.T, fixed: msg.fixed}, this.group);
    anchor.add(object);
    this.scene.invalidate();
  }
}

export class PathDisplay extends StampedDisplay {
  static defaults = {color: "#19ff00", width: 0.03};
  static fields = [["color", "color", "color"], ["width", "width (m)", "number", {min: 0, step: 0.01}]];

  data(msg) {
    this.last = msg;
    this.show(msg, lines(msg.points, Number(this.options.width), hexColor(this.options.color), null, true));
  }

  applyOptions() {
    if (this.last) this.data(this.last);
  }
}

export class PolygonDisplay extends PathDisplay {
  data(msg) {
    this.last = msg;
    const points = msg.points.length >= 6 ? [...msg.points, ...msg.points.slice(0, 3)] : msg.points;
    this.show(msg, lines(points, Number(this.options.width), hexColor(this.options.color), null, true));
  }
}

export class PoseDisplay extends StampedDisplay {
  static defaults = {color: "#ff1900", length: 1};
  static fields = [["color", "color", "color"], ["length", "shaft length (m)", "number", {min: 0.01, step: 0.1}]];

  data(msg) {
    this.last = msg;
    const length = Number(this.options.length) || 1;
    // Rviz's Pose arrow: shaft 1 m long, 0.1 m across; head 0.3 m long, 0.2 m across
    const object = arrow(length + 0.3 * length, 0.1 * length, 0.2 * length, 0.3 * length, hexColor(this.options.color));
    setPose(object, msg.pose);
    this.show(msg, object);
  }

  applyOptions() {
    if (this.last) this.data(this.last);
  }
}

export class PoseArrayDisplay extends StampedDisplay {
  static defaults = {color: "#ff1900", length: 0.3};
  static fields = [["color", "color", "color"], ["length", "arrow length (m)", "number", {min: 0.01, step: 0.05}]];

  data(msg) {
    this.last = msg;
    const length = Number(this.options.length) || 0.3;
    const mesh = new THREE.InstancedMesh(ARROW, material(hexColor(this.options.color)), Math.max(msg.poses.length, 1));
    mesh.count = msg.poses.length;
    const scale = new THREE.Vector3(length, length * 0.2, length * 0.2);
    msg.poses.forEach((p, i) => {
      const m = poseMatrix(p);
      m.scale(scale);
      mesh.setMatrixAt(i, m);
    });
    mesh.computeBoundingSphere();
    this.show(msg, mesh);
  }

  applyOptions() {
    if (this.last) this.data(this.last);
  }
}

export class OdometryDisplay extends Display {
  static defaults = {color: "#ff1900", keep: 100, length: 0.4};
  static fields = [["color", "color", "color"], ["keep", "keep", "number", {min: 1, max: 10000, step: 1}],
                   ["length", "arrow length (m)", "number", {min: 0.01, step: 0.1}]];

  constructor(view, config) {
    super(view, config);
    this.arrows = [];
  }

  data(msg) {
    this.received++;
    // Rviz keeps an arrow when the robot moved 0.1 m or turned 0.1 rad since the last one
    const matrix = poseMatrix(msg.pose);
    const last = this.arrows[this.arrows.length - 1];
    if (last && last.fixed === msg.fixed && last.frame === msg.frame) {
      const a = new THREE.Vector3().setFromMatrixPosition(last.matrix);
      const b = new THREE.Vector3().setFromMatrixPosition(matrix);
      const qa = new THREE.Quaternion().setFromRotationMatrix(last.matrix);
      const qb = new THREE.Quaternion().setFromRotationMatrix(matrix);
      if (a.distanceTo(b) < 0.1 && qa.angleTo(qb) < 0.1) return;
    }
    const length = Number(this.options.length) || 0.4;
    const object = new THREE.Mesh(ARROW, material(hexColor(this.options.color)));
    object.scale.set(length, length * 0.15, length * 0.15);
    setPose(object, msg.pose);
    const anchor = this.scene.anchor({frame: msg.frame, T: msg.T, fixed: msg.fixed}, this.group);
    anchor.add(object);
    this.arrows.push({anchor, matrix, fixed: msg.fixed, frame: msg.frame});
    while (this.arrows.length > Math.max(1, Number(this.options.keep) || 100)) dispose(this.arrows.shift().anchor);
    this.scene.invalidate();
  }

  clear() {
    super.clear();
    this.arrows = [];
  }
}
