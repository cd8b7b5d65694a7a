// Shapes the 3D view draws: arrows, axes, lines with a width, text labels, Rviz's markers
// (every visualization_msgs/Marker type) and meshes loaded from the server (STL, COLLADA, OBJ).
//
// buildMarker(m, meshes) makes the object of one marker as scenedata.marker_json sends it, in
// the marker's own pose (its anchor gives the frame). Geometries used by many objects are
// shared (userData.shared) and never disposed.

import * as THREE from "three";
import {STLLoader} from "../../vendor/three/examples/jsm/loaders/STLLoader.js";
import {ColladaLoader} from "../../vendor/three/examples/jsm/loaders/ColladaLoader.js";
import {OBJLoader} from "../../vendor/three/examples/jsm/loaders/OBJLoader.js";
import {serverUrl} from "../conn.js";
import {setPose} from "./scene.js";

export {dispose} from "./scene.js";

function shared(geometry) {
  geometry.userData.shared = true;
  return geometry;
}

const BOX = shared(new THREE.BoxGeometry(1, 1, 1));
const SPHERE = shared(new THREE.SphereGeometry(0.5, 20, 14));
const SMALL_SPHERE = shared(new THREE.SphereGeometry(0.5, 10, 6));
const CYLINDER = shared(new THREE.CylinderGeometry(0.5, 0.5, 1, 20).rotateX(Math.PI / 2));  // axis z
const SEGMENT = shared(new THREE.CylinderGeometry(0.5, 0.5, 1, 6, 1, true)
  .translate(0, 0.5, 0).rotateX(Math.PI / 2));  // from (0,0,0) to (0,0,1)

/** An arrow along +x from 0 to 1 (shaft to 0.77, half as wide as the head), one geometry. */
function arrowGeometry(shaft = 0.25, head = 0.5, headStart = 0.77) {
  const profile = [[0, 0], [shaft, 0], [shaft, headStart], [head, headStart], [0, 1]]
    .map(([r, y]) => new THREE.Vector2(r, y));
  return new THREE.LatheGeometry(profile, 16).rotateZ(-Math.PI / 2);
}
export const ARROW = shared(arrowGeometry());

export function material(color, opts = {}) {
  const [r, g, b, a] = color || [1, 1, 1, 1];
  const m = new THREE.MeshLambertMaterial({color: new THREE.Color(r, g, b)});
  if (opts.side !== undefined) m.side = opts.side;
  if (a < 1) {
    m.transparent = true;
    m.opacity = Math.max(a, 0);
    m.depthWrite = false;
  }
  return m;
}

export function flatMaterial(color) {
  const [r, g, b, a] = color || [1, 1, 1, 1];
  const m = new THREE.MeshBasicMaterial({color: new THREE.Color(r, g, b)});
  if (a < 1) Object.assign(m, {transparent: true, opacity: Math.max(a, 0), depthWrite: false});
  return m;
}

/** An arrow of `length` along +x: shaft diameter and head diameter and length in metres. */
export function arrow(length, shaftDiameter, headDiameter, headLength, color) {
  const group = new THREE.Group();
  const mat = material(color);
  const shaftLength = Math.max(length - headLength, 0);
  const shaft = new THREE.Mesh(CYLINDER, mat);
  shaft.rotation.y = Math.PI / 2;
  shaft.scale.set(shaftDiameter, shaftDiameter, shaftLength);
  shaft.position.x = shaftLength / 2;
  const cone = new THREE.Mesh(new THREE.ConeGeometry(0.5, 1, 16).rotateZ(-Math.PI / 2), mat);
  cone.scale.set(headLength, headDiameter, headDiameter);
  cone.position.x = shaftLength + headLength / 2;
  group.add(shaft, cone);
  return group;
}

/** x (red), y (green), z (blue) axes of `length`. */
export function axes(length, radius) {
  const group = new THREE.Group();
  const colors = [[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1]];
  colors.forEach((color, i) => {
    const mesh = new THREE.Mesh(CYLINDER, material(color));
    mesh.scale.set(radius * 2, radius * 2, length);
    if (i === 0) mesh.rotation.y = Math.PI / 2;
    if (i === 1) mesh.rotation.x = -Math.PI / 2;
    mesh.position.setComponent(i, length / 2);
    group.add(mesh);
  });
  return group;
}

/** A text label facing the camera, `height` metres tall. */
export function label(text, height, color = [1, 1, 1, 1]) {
  const font = 48;
  const canvas = document.createElement("canvas");
  const ctx = canvas.getContext("2d");
  ctx.font = `${font}px system-ui, sans-serif`;
  const lines = String(text).split("\n");
  const width = Math.max(1, ...lines.map((l) => ctx.measureText(l).width));
  canvas.width = Math.ceil(width) + 8;
  canvas.height = font * 1.25 * lines.length + 8;
  ctx.font = `${font}px system-ui, sans-serif`;
  ctx.fillStyle = `rgba(${color.slice(0, 3).map((c) => Math.round(c * 255)).join(",")},1)`;
  ctx.textBaseline = "top";
  lines.forEach((line, i) => ctx.fillText(line, 4, 4 + i * font * 1.25));
  const texture = new THREE.CanvasTexture(canvas);
  texture.colorSpace = THREE.SRGBColorSpace;
  const sprite = new THREE.Sprite(new THREE.SpriteMaterial({
    map: texture, transparent: true, opacity: color[3] ?? 1, depthWrite: false}));
  sprite.scale.set(height * canvas.width / canvas.height, height, 1);
  sprite.userData.text = text;
  return sprite;
}

/** Segments a-b (3 numbers each in `points`) drawn as cylinders `width` wide, one instanced
 * mesh; `colors` (4 per point) colour each segment by its first point. strip: a polyline. */
export function lines(points, width, color, colors, strip) {
  const count = points.length / 3;
  const pairs = [];
  if (strip) for (let i = 0; i + 1 < count; i++) pairs.push([i, i + 1]);
  else for (let i = 0; i + 1 < count; i += 2) pairs.push([i, i + 1]);
  if (pairs.length > 50000 || width <= 0) {  // many: 1-pixel lines
    const positions = new Float32Array(pairs.length * 6);
    pairs.forEach(([a, b], i) => {
      positions.set(points.slice(a * 3, a * 3 + 3), i * 6);
      positions.set(points.slice(b * 3, b * 3 + 3), i * 6 + 3);
    });
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.BufferAttribute(positions, 3));
    const [r, g, b] = color;
    return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({color: new THREE.Color(r, g, b)}));
  }
  const mesh = new THREE.InstancedMesh(SEGMENT, material(color), Math.max(pairs.length, 1));
  mesh.count = pairs.length;
  const a = new THREE.Vector3();
  const b = new THREE.Vector3();
  const m = new THREE.Matrix4();
  const q = new THREE.Quaternion();
  const z = new THREE.Vector3(0, 0, 1);
  const dir = new THREE.Vector3();
  const scale = new THREE.Vector3();
  pairs.forEach(([i, j], k) => {
    a.fromArray(points, i * 3);
    b.fromArray(points, j * 3);
    dir.subVectors(b, a);
    const length = dir.length();
    q.setFromUnitVectors(z, length > 0 ? dir.divideScalar(length) : z);
    m.compose(a, q, scale.set(width, width, length));
    mesh.setMatrixAt(k, m);
    if (colors) mesh.setColorAt(k, new THREE.Color(colors[i * 4], colors[i * 4 + 1], colors[i * 4 + 2]));
  });
  mesh.instanceMatrix.needsUpdate = true;
  mesh.computeBoundingSphere();
  return mesh;
}

/** One instanced shape per point (cube_list, sphere_list). */
function instances(geometry, m, scale) {
  const count = m.points.length / 3;
  const mesh = new THREE.InstancedMesh(geometry, material(m.color), Math.max(count, 1));
  mesh.count = count;
  const matrix = new THREE.Matrix4();
  const p = new THREE.Vector3();
  const s = new THREE.Vector3(...scale);
  const q = new THREE.Quaternion();
  for (let i = 0; i < count; i++) {
    mesh.setMatrixAt(i, matrix.compose(p.fromArray(m.points, i * 3), q, s));
    if (m.colors) mesh.setColorAt(i, new THREE.Color(m.colors[i * 4], m.colors[i * 4 + 1], m.colors[i * 4 + 2]));
  }
  mesh.computeBoundingSphere();
  return mesh;
}

/** The object of one marker (marker_json), in the marker's pose. */
export function buildMarker(m, meshes) {
  const [sx, sy, sz] = m.scale;
  let object;
  switch (m.type) {
    case "arrow":
      if (m.points && m.points.length >= 6) {  // from the first point to the second
        const a = new THREE.Vector3().fromArray(m.points, 0);
        const b = new THREE.Vector3().fromArray(m.points, 3);
        const length = a.distanceTo(b);
        const head = sz > 0 ? sz : 0.23 * length;
        object = arrow(length, sx, sy, Math.min(head, length), m.color);
        object.position.copy(a);
        object.quaternion.setFromUnitVectors(new THREE.Vector3(1, 0, 0), b.clone().sub(a).normalize());
        const holder = new THREE.Group();
        holder.add(object);
        object = holder;
      } else {
        object = new THREE.Mesh(ARROW, material(m.color));
        object.scale.set(sx, sy, sz);
      }
      break;
    case "cube":
    case "sphere":
    case "cylinder":
      object = new THREE.Mesh({cube: BOX, sphere: SPHERE, cylinder: CYLINDER}[m.type], material(m.color));
      object.scale.set(sx, sy, sz);
      break;
    case "line_strip":
    case "line_list":
      object = lines(m.points || [], sx, m.color, m.colors, m.type === "line_strip");
      break;
    case "cube_list":
      object = instances(BOX, m, [sx, sy, sz]);
      break;
    case "sphere_list":
      object = instances((m.points || []).length > 3000 ? SMALL_SPHERE : SPHERE, m, [sx, sy, sz]);
      break;
    case "points": {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute("position", new THREE.Float32BufferAttribute(m.points || [], 3));
      const mat = new THREE.PointsMaterial({size: sx || 0.05, sizeAttenuation: true});
      if (m.colors) {
        const rgb = [];
        for (let i = 0; i < m.colors.length; i += 4) rgb.push(m.colors[i], m.colors[i + 1], m.colors[i + 2]);
        geometry.setAttribute("color", new THREE.Float32BufferAttribute(rgb, 3));
        mat.vertexColors = true;
      } else {
        mat.color.setRGB(m.color[0], m.color[1], m.color[2]);
      }
      if (m.color[3] < 1) Object.assign(mat, {transparent: true, opacity: m.color[3]});
      object = new THREE.Points(geometry, mat);
      object.frustumCulled = false;
      break;
    }
    case "text":
      object = label(m.text || "", sz || 0.1, m.color);
      break;
    case "mesh":
      object = new THREE.Group();
      object.scale.set(sx, sy, sz);
      meshes.add(object, m.mesh, m.embedded_materials && m.color[3] === 0 ? null : m.color,
                 m.embedded_materials);
      break;
    case "triangle_list": {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute("position", new THREE.Float32BufferAttribute(m.points || [], 3));
      let mat;
      if (m.colors) {
        const rgb = [];
        for (let i = 0; i < m.colors.length; i += 4) rgb.push(m.colors[i], m.colors[i + 1], m.colors[i + 2]);
        geometry.setAttribute("color", new THREE.Float32BufferAttribute(rgb, 3));
        mat = material([1, 1, 1, m.color[3]], {side: THREE.DoubleSide});
        mat.vertexColors = true;
      } else {
        mat = material(m.color, {side: THREE.DoubleSide});
      }
      geometry.computeVertexNormals();
      object = new THREE.Mesh(geometry, mat);
      object.scale.set(sx, sy, sz);
      break;
    }
    default:
      object = new THREE.Group();
  }
  const holder = new THREE.Group();
  setPose(holder, m.pose);
  holder.add(object);
  return holder;
}

/**
 * Meshes loaded once per URL from the server (/pkg/... with the page's token), cloned for each
 * use. add(parent, url, color, embedded) hangs the mesh under `parent` when it arrives: with
 * `color` on every surface unless `embedded` and the file has its own materials. Problems go
 * to onError(url, text).
 */
export class MeshCache {
  constructor(onLoaded) {
    this.onLoaded = onLoaded || (() => {});
    this.loaded = new Map();   // url -> Promise<Object3D>
    this.errors = new Map();   // url -> text
    this.pending = 0;
    this.manager = new THREE.LoadingManager();
    // a COLLADA file's textures are found beside it: they need the token too
    this.manager.setURLModifier((url) => (url.startsWith("/pkg/") || url.includes("/pkg/"))
      && !url.includes("token=") ? withToken(url) : url);
  }

  load(url) {
    let promise = this.loaded.get(url);
    if (promise) return promise;
    const kind = url.split("?")[0].split(".").pop().toLowerCase();
    this.pending++;
    promise = new Promise((resolve, reject) => {
      const done = (object) => {
        object.traverse((o) => {
          if (o.geometry) o.geometry.userData.shared = true;
          const mats = Array.isArray(o.material) ? o.material : o.material ? [o.material] : [];
          for (const mat of mats) {
            mat.userData.shared = true;
            if (mat.map) mat.map.userData.shared = true;
          }
        });
        resolve(object);
      };
      const fail = (err) => reject(new Error(err && err.message ? err.message : `cannot load ${url}`));
      const target = url;  // the manager's URL modifier adds the token
      if (kind === "stl") {
        new STLLoader(this.manager).load(target, (geometry) => {
          geometry.computeVertexNormals();
          const mesh = new THREE.Mesh(geometry, material([0.8, 0.8, 0.8, 1]));
          mesh.userData.plain = true;  // no materials of its own
          done(mesh);
        }, undefined, fail);
      } else if (kind === "dae") {
        new ColladaLoader(this.manager).load(target, (collada) => {
          if (!collada) return fail(new Error(`${url} is not a COLLADA file`));
          const scene = collada.scene;
          // ROS is z-up: keep a Z_UP file as authored (undo the loader's turn to y-up) and
          // stand a Y_UP one up
          if (Math.abs(scene.rotation.x + Math.PI / 2) < 1e-6) scene.rotation.x = 0;
          else scene.rotation.x = Math.PI / 2;
          const holder = new THREE.Group();
          holder.add(scene);
          done(holder);
        }, undefined, fail);
      } else if (kind === "obj") {
        new OBJLoader(this.manager).load(target, (group) => {
          group.userData.plain = true;
          done(group);
        }, undefined, fail);
      } else {
        reject(new Error(`${url}: the view loads .stl, .dae and .obj meshes`));
      }
    }).finally(() => { this.pending--; });
    this.loaded.set(url, promise);
    return promise;
  }

  add(parent, url, color, embedded, onError) {
    this.load(url).then((object) => {
      const copy = object.clone();
      if (color && (!embedded || object.userData.plain)) {
        const mat = material(color);
        copy.traverse((o) => { if (o.isMesh) o.material = mat; });
      }
      parent.add(copy);
      this.onLoaded(url);
    }).catch((err) => {
      this.errors.set(url, err.message);
      if (onError) onError(url, err.message);
      this.onLoaded(url);
    });
  }
}

export function withToken(url) {
  const [path, query] = url.split("?");
  const params = Object.fromEntries(new URLSearchParams(query || ""));
  return serverUrl(path, params);
}
