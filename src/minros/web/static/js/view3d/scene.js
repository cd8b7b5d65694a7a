// The 3D view's WebGL scene: renderer, orbit camera, grid, lights, and where things go.
//
// The scene's coordinates are the fixed frame's, z up, as in Rviz. tf frames' poses in the fixed
// frame come from the server (scene_frames); data is hung from *anchors*: groups whose matrix is
// the pose of the data's frame, either as the server looked it up at the message's stamp (T, in
// the fixed frame of that moment) or, for data locked to its frame, the frame's latest pose.
// Anchors are placed again whenever frames or the fixed frame change; an anchor that cannot be
// placed (its frame is not connected to the fixed frame) is hidden.
//
// Rendering happens on demand (something changed, the camera moved), or every frame while
// `continuous` is set; `stats` counts the frames drawn per second.

import * as THREE from "three";
import {OrbitControls} from "../../vendor/three/examples/jsm/controls/OrbitControls.js";

const ONE = new THREE.Vector3(1, 1, 1);
const _v = new THREE.Vector3();
const _q = new THREE.Quaternion();

/** The matrix of a pose [x, y, z, qx, qy, qz, qw]. */
export function poseMatrix(p, out = new THREE.Matrix4()) {
  return out.compose(_v.set(p[0], p[1], p[2]), _q.set(p[3], p[4], p[5], p[6]), ONE);
}

/** Set an object's position and rotation from a pose. */
export function setPose(object, p) {
  object.position.set(p[0], p[1], p[2]);
  object.quaternion.set(p[3], p[4], p[5], p[6]);
}

/** A pose [x, y, z, qx, qy, qz, qw] of a matrix. */
export function matrixPose(m) {
  const position = new THREE.Vector3();
  const rotation = new THREE.Quaternion();
  m.decompose(position, rotation, new THREE.Vector3());
  return [position.x, position.y, position.z, rotation.x, rotation.y, rotation.z, rotation.w];
}

export class Scene3D {
  constructor(container) {
    this.container = container;
    // without a GPU (the browser's software renderer) every pixel costs CPU: no antialiasing,
    // one sample per CSS pixel
    this.software = softwareRenderer();
    this.renderer = new THREE.WebGLRenderer({antialias: !this.software});
    this.renderer.setPixelRatio(this.software ? 1 : Math.min(window.devicePixelRatio || 1, 2));
    this.canvas = this.renderer.domElement;
    this.canvas.classList.add("scene-canvas");
    container.append(this.canvas);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x303030);  // Rviz's background (48, 48, 48)
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.02, 2000);
    this.camera.up.set(0, 0, 1);
    this.scene.add(this.camera);
    this.scene.add(new THREE.AmbientLight(0xffffff, 0.55));
    const light = new THREE.DirectionalLight(0xffffff, 1.6);  // from the eye, as Rviz lights it
    light.position.set(0, 0, 0);
    light.target.position.set(0, 0, -1);
    this.camera.add(light, light.target);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.screenSpacePanning = false;  // panning slides along the ground
    this.lastMove = -1e9;
    this.controls.addEventListener("change", () => {
      this.lastMove = performance.now();
      this.invalidate();
    });
    this.resetCamera();
    this.grid = new THREE.GridHelper(10, 10, 0xa0a0a4, 0xa0a0a4);  // Rviz's grid: 10 cells of 1 m
    this.grid.rotation.x = Math.PI / 2;
    this.scene.add(this.grid);

    this.fixed = "";
    this.frames = new Map();      // name -> {T, parent, age, stale, matrix}
    this.anchors = new Set();
    this.beforeRender = new Set(); // callbacks(now) run before each render (lifetimes, labels)
    this.dirty = true;
    this.continuous = false;
    this.visible = false;
    this.raf = null;
    this.stats = {fps: 0, frames: 0, rendered: 0, width: 0, height: 0, renderer: this.software || "GPU"};
    this._count = 0;
    this._since = performance.now();
    new ResizeObserver(() => this.resize()).observe(container);
  }

  resetCamera() {
    // Rviz's orbit view: 10 m from the focus, yaw and pitch 45 degrees
    this.camera.position.set(5, 5, 7.07);
    this.controls.target.set(0, 0, 0);
    this.controls.update();
    this.invalidate();
  }

  resize() {
    const width = this.container.clientWidth;
    const height = this.container.clientHeight;
    if (!width || !height) return;
    this.renderer.setSize(width, height, false);
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
    this.stats.width = width;
    this.stats.height = height;
    this.invalidate();
  }

  invalidate() {
    this.dirty = true;
  }

  /** Whether the camera moved in the last quarter of a second (big clouds draw coarser then
   * on a software renderer, see PointsDisplay). */
  get moving() {
    return performance.now() - this.lastMove < 250;
  }

  show() {
    this.visible = true;
    this.resize();
    if (!this.raf) this.raf = requestAnimationFrame((t) => this.loop(t));
  }

  hide() {
    this.visible = false;
  }

  loop(now) {
    this.raf = this.visible ? requestAnimationFrame((t) => this.loop(t)) : null;
    for (const cb of this.beforeRender) cb(now);
    const moving = this.moving;
    if (this.wasMoving && !moving) this.invalidate();  // the camera stopped: draw it all again
    this.wasMoving = moving;
    if (this.dirty || this.continuous) {
      this.dirty = false;
      this.renderer.render(this.scene, this.camera);
      this._count++;
      this.stats.rendered++;
    }
    if (now - this._since >= 1000) {
      this.stats.fps = Math.round(this._count * 10000 / (now - this._since)) / 10;
      this._count = 0;
      this._since = now;
    }
  }

  // -- tf --------------------------------------------------------------------------------

  /** A scene_frames message: every frame's latest pose in the fixed frame. */
  setFrames(msg) {
    const changedFixed = msg.fixed !== this.fixed;
    this.fixed = msg.fixed;
    const frames = new Map();
    for (const f of msg.frames) {
      frames.set(f.name, {...f, matrix: f.T ? poseMatrix(f.T) : null});
    }
    this.frames = frames;
    this.stats.frames = frames.size;
    this.placeAll();
    return changedFixed;
  }

  /** The latest pose (Matrix4) of a frame in the fixed frame, or null. */
  frameMatrix(name) {
    if (name === this.fixed || name === "") return IDENTITY;
    const f = this.frames.get(name);
    return f ? f.matrix : null;
  }

  /** A group hung at `place` = {frame, T, fixed, locked}; placed now and whenever tf moves. */
  anchor(place, parent) {
    const group = new THREE.Group();
    group.matrixAutoUpdate = false;
    group.userData.place = place;
    this.anchors.add(group);
    parent.add(group);
    this.placeAnchor(group);
    return group;
  }

  placeAnchor(group) {
    const place = group.userData.place;
    let matrix = null;
    if (place.locked) {
      matrix = this.frameMatrix(place.frame);
    } else if (place.T) {
      if (place.fixed === this.fixed) {
        matrix = poseMatrix(place.T, group.matrix);
      } else {  // looked up in another fixed frame: re-root through that frame's pose now
        const root = this.frameMatrix(place.fixed);
        matrix = root ? group.matrix.multiplyMatrices(root, poseMatrix(place.T)) : null;
      }
    }
    if (matrix && matrix !== group.matrix) group.matrix.copy(matrix);
    group.visible = Boolean(matrix);
    group.matrixWorldNeedsUpdate = true;
    return group.visible;
  }

  placeAll() {
    for (const group of this.anchors) {
      if (inScene(group, this.scene)) this.placeAnchor(group);
      else this.anchors.delete(group);  // its display dropped it
    }
    this.invalidate();
  }

  // -- picking ---------------------------------------------------------------------------

  /** The ray under a pointer event. */
  ray(event) {
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
                                  -((event.clientY - rect.top) / rect.height) * 2 + 1);
    const raycaster = new THREE.Raycaster();
    raycaster.setFromCamera(ndc, this.camera);
    return raycaster;
  }

  /** Where a pointer event's ray meets the ground (z = 0 of the fixed frame), or null. */
  ground(event) {
    const hit = new THREE.Vector3();
    return this.ray(event).ray.intersectPlane(GROUND, hit) ? hit : null;
  }

  /** Look at `target` from `eye` (points of the fixed frame). */
  lookAt(target, eye) {
    this.controls.target.set(...target);
    this.camera.position.set(...eye);
    this.controls.update();
    this.invalidate();
  }

  /** The colour [r, g, b, a] drawn at page coordinates (x, y): rendered now and read back. */
  pixel(x, y) {
    this.renderer.render(this.scene, this.camera);
    const rect = this.canvas.getBoundingClientRect();
    const ratio = this.renderer.getPixelRatio();
    const gl = this.renderer.getContext();
    const out = new Uint8Array(4);
    gl.readPixels(Math.round((x - rect.left) * ratio), Math.round((rect.bottom - y) * ratio), 1, 1,
                  gl.RGBA, gl.UNSIGNED_BYTE, out);
    return [...out];
  }

  /** Page coordinates of a point of the fixed frame (for tests and labels). */
  project(x, y, z) {
    // the camera's matrices follow its pose only at a render: bring them up to date, so a point
    // projected right after lookAt (before the next frame is drawn) is where it will be drawn
    this.camera.updateMatrixWorld();
    const v = new THREE.Vector3(x, y, z).project(this.camera);
    const rect = this.canvas.getBoundingClientRect();
    return {x: rect.left + (v.x + 1) / 2 * rect.width, y: rect.top + (1 - v.y) / 2 * rect.height,
            inside: Math.abs(v.x) <= 1 && Math.abs(v.y) <= 1 && v.z < 1};
  }
}

/** The name of the software WebGL renderer the browser uses, or "" with a GPU. */
function softwareRenderer() {
  try {
    const gl = document.createElement("canvas").getContext("webgl2");
    if (!gl) return "";
    const info = gl.getExtension("WEBGL_debug_renderer_info");
    const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
    const lose = gl.getExtension("WEBGL_lose_context");
    if (lose) lose.loseContext();
    return /swiftshader|llvmpipe|softpipe|software/i.test(name) ? name : "";
  } catch (err) {
    return "";
  }
}

function inScene(object, scene) {
  for (let o = object; o; o = o.parent) if (o === scene) return true;
  return false;
}

/** Free the GPU resources of an object's tree (geometries, materials and textures not marked
 * userData.shared) and take it out of its parent. */
export function dispose(object) {
  if (!object) return;
  object.removeFromParent();
  object.traverse((o) => {
    if (o.geometry && !o.geometry.userData.shared) o.geometry.dispose();
    const materials = Array.isArray(o.material) ? o.material : o.material ? [o.material] : [];
    for (const m of materials) {
      if (m.userData.shared) continue;
      if (m.map && !m.map.userData.shared) m.map.dispose();
      m.dispose();
    }
  });
}

const IDENTITY = new THREE.Matrix4();
const GROUND = new THREE.Plane(new THREE.Vector3(0, 0, 1), 0);
