// Interactive markers (the server of minros's or ROS's interactive_markers): drawn from the
// server's update_full/update as Rviz draws them, and dragged with the mouse. While a control is
// dragged, the marker follows the pointer here and its new pose (in the fixed frame) goes to the
// minros web server as im_feedback, which publishes InteractiveMarkerFeedback in the marker's
// frame: MOUSE_DOWN, POSE_UPDATE at most 30 times a second, MOUSE_UP; a BUTTON control sends
// BUTTON_CLICK.
//
// Controls without markers get Rviz's: arrows for MOVE_AXIS, a ring for ROTATE_AXIS and
// MOVE_ROTATE, a disc for MOVE_PLANE, a box for MOVE_3D (coloured by the axis: x red, y green,
// z blue). The control's axis is x of its orientation, turned by the marker's own unless the
// orientation mode is FIXED.

import * as THREE from "three";
import {Display} from "./displays.js";
import {buildMarker, dispose, label, material} from "./shapes.js";
import {matrixPose, setPose} from "./scene.js";

// visualization_msgs/InteractiveMarkerControl
const INHERIT = 0, FIXED = 1, VIEW_FACING = 2;
const NONE = 0, MENU = 1, BUTTON = 2, MOVE_AXIS = 3, MOVE_PLANE = 4, ROTATE_AXIS = 5,
  MOVE_ROTATE = 6, MOVE_3D = 7, ROTATE_3D = 8, MOVE_ROTATE_3D = 9;
// visualization_msgs/InteractiveMarkerFeedback
export const FEEDBACK = {KEEP_ALIVE: 0, POSE_UPDATE: 1, MENU_SELECT: 2, BUTTON_CLICK: 3,
                         MOUSE_DOWN: 4, MOUSE_UP: 5};
const X = new THREE.Vector3(1, 0, 0);

function axisColor(q) {
  const axis = X.clone().applyQuaternion(q);
  const [x, y, z] = [Math.abs(axis.x), Math.abs(axis.y), Math.abs(axis.z)];
  if (x >= y && x >= z) return [0.9, 0.15, 0.15, 0.85];
  if (y >= z) return [0.15, 0.8, 0.15, 0.85];
  return [0.2, 0.35, 0.95, 0.85];
}

/** Rviz's markers for a control that brings none, in the control's orientation. */
function defaultMarkers(control, scale) {
  const q = new THREE.Quaternion(...control.orientation);
  const color = axisColor(q);
  const group = new THREE.Group();
  group.quaternion.copy(q);
  const mode = control.interaction_mode;
  if (mode === MOVE_AXIS) {
    for (const sign of [1, -1]) {
      const cone = new THREE.Mesh(new THREE.ConeGeometry(0.12 * scale, 0.35 * scale, 20), material(color));
      cone.rotation.z = -sign * Math.PI / 2;
      cone.position.x = sign * 0.7 * scale;
      group.add(cone);
    }
  } else if (mode === ROTATE_AXIS || mode === MOVE_ROTATE) {
    const ring = new THREE.Mesh(new THREE.TorusGeometry(0.6 * scale, 0.05 * scale, 8, 48), material(color));
    ring.rotation.y = Math.PI / 2;  // in the plane normal to x
    group.add(ring);
  } else if (mode === MOVE_PLANE) {
    const disc = new THREE.Mesh(new THREE.RingGeometry(0.5 * scale, 0.65 * scale, 48),
                                material(color, {side: THREE.DoubleSide}));
    disc.rotation.y = Math.PI / 2;
    group.add(disc);
  } else if (mode === MOVE_3D || mode === ROTATE_3D || mode === MOVE_ROTATE_3D) {
    const box = new THREE.Mesh(new THREE.BoxGeometry(0.3 * scale, 0.3 * scale, 0.3 * scale), material(color));
    group.add(box);
  }
  return group;
}

export class InteractiveMarkersDisplay extends Display {
  static defaults = {descriptions: true};
  static fields = [["descriptions", "descriptions", "checkbox"]];

  constructor(view, config) {
    super(view, config);
    this.markers = new Map();  // name -> {anchor, root, data}
    this.dragging = null;      // the name of the marker being dragged
    this.meshes = view.meshes;
  }

  data(msg) {
    this.received++;
    const seen = new Set();
    for (const im of msg.imarkers) {
      seen.add(im.name);
      if (im.name === this.dragging) continue;  // the pointer moves it
      const old = this.markers.get(im.name);
      if (old) dispose(old.anchor);
      const anchor = this.scene.anchor({frame: im.frame, T: im.T, fixed: msg.fixed, locked: im.locked}, this.group);
      const root = new THREE.Group();  // the interactive marker's pose in its frame
      setPose(root, im.pose);
      anchor.add(root);
      for (const control of im.controls) {
        const holder = new THREE.Group();
        holder.userData.control = control;
        if (control.orientation_mode === FIXED) holder.userData.fixedOrientation = true;
        if (control.markers.length) {
          for (const m of control.markers) holder.add(buildMarker(m, this.meshes));
        } else if (control.interaction_mode !== NONE && control.interaction_mode !== MENU) {
          holder.add(defaultMarkers(control, im.scale));
        }
        holder.traverse((o) => { o.userData.im = im.name; o.userData.control = control; });
        root.add(holder);
      }
      if (this.options.descriptions && im.description) {
        const text = label(im.description, 0.1 * im.scale);
        text.position.set(0, 0, 0.6 * im.scale);
        root.add(text);
      }
      this.markers.set(im.name, {anchor, root, data: im, fixed: msg.fixed});
    }
    for (const [name, entry] of this.markers) {
      if (!seen.has(name)) {
        dispose(entry.anchor);
        this.markers.delete(name);
      }
    }
    this.framesChanged();
    this.scene.invalidate();
  }

  framesChanged() {
    // a FIXED control keeps its orientation in the frame whatever the marker's own turn
    for (const entry of this.markers.values()) {
      for (const holder of entry.root.children) {
        if (holder.userData.fixedOrientation) holder.quaternion.copy(entry.root.quaternion).invert();
      }
    }
  }

  /** The world pose [x, y, z, qx, qy, qz, qw] of marker `name`. */
  worldPose(name) {
    const entry = this.markers.get(name);
    entry.root.updateWorldMatrix(true, false);
    return matrixPose(entry.root.matrixWorld);
  }

  /** The control object hit by a ray: {name, control, point} or null. */
  pick(raycaster) {
    const hits = raycaster.intersectObject(this.group, true).filter((h) => h.object.userData.control &&
      h.object.userData.control.interaction_mode !== NONE && h.object.visible);
    if (!hits.length) return null;
    const hit = hits[0];
    return {display: this, name: hit.object.userData.im, control: hit.object.userData.control, point: hit.point};
  }
}

/** Dragging interactive markers with the pointer (left button), feedback to the server. */
export class Dragger {
  constructor(view) {
    this.view = view;
    this.scene = view.scene3d;
    this.drag = null;
    this.lastSent = 0;
    const canvas = this.scene.canvas;
    canvas.addEventListener("pointerdown", (e) => this.down(e), true);
    canvas.addEventListener("pointermove", (e) => this.move(e), true);
    canvas.addEventListener("pointerup", (e) => this.up(e), true);
    canvas.addEventListener("pointercancel", (e) => this.up(e), true);
  }

  feedback(hit, event, pose) {
    this.view.app.conn.send({op: "im_feedback", id: hit.display.id, marker: hit.name,
                             control: hit.control.name, event, ...(pose ? {pose} : {})});
  }

  down(event) {
    if (event.button !== 0 || this.view.tool !== "interact") return;
    const raycaster = this.scene.ray(event);
    let hit = null;
    for (const display of this.view.displays) {
      if (display instanceof InteractiveMarkersDisplay && display.enabled) {
        const found = display.pick(raycaster);
        if (found && (!hit || raycaster.ray.origin.distanceTo(found.point) < raycaster.ray.origin.distanceTo(hit.point))) hit = found;
      }
    }
    if (!hit) return;
    event.stopImmediatePropagation();
    event.preventDefault();
    this.scene.canvas.setPointerCapture(event.pointerId);
    this.scene.controls.enabled = false;
    const entry = hit.display.markers.get(hit.name);
    const start = entry.root.matrixWorld.clone();
    const position = new THREE.Vector3().setFromMatrixPosition(start);
    const rotation = new THREE.Quaternion().setFromRotationMatrix(start);
    const controlQ = new THREE.Quaternion(...hit.control.orientation);
    // the control's axis in the world: x of its orientation, in the marker's frame turned by
    // the marker (INHERIT) or not (FIXED)
    const frameQ = new THREE.Quaternion().setFromRotationMatrix(entry.anchor.matrixWorld);
    const base = hit.control.orientation_mode === FIXED ? frameQ : rotation;
    const axis = X.clone().applyQuaternion(base.clone().multiply(controlQ)).normalize();
    const mode = hit.control.interaction_mode;
    const planeNormal = mode === MOVE_3D || mode === ROTATE_3D || mode === MOVE_ROTATE_3D
      ? this.scene.camera.getWorldDirection(new THREE.Vector3()).negate() : axis.clone();
    this.drag = {hit, entry, position, rotation, axis, mode, start,
                 plane: new THREE.Plane().setFromNormalAndCoplanarPoint(planeNormal, hit.point),
                 startPoint: hit.point.clone(), startT: this.axisParam(raycaster.ray, position, axis),
                 moved: false};
    hit.display.dragging = hit.name;
    if (mode === BUTTON) return;
    this.feedback(hit, FEEDBACK.MOUSE_DOWN, matrixPose(start));
  }

  /** Where along the axis line (through `origin`) the ray passes closest. */
  axisParam(ray, origin, axis) {
    const w0 = ray.origin.clone().sub(origin);
    const b = ray.direction.dot(axis);
    const d = ray.direction.dot(w0);
    const e = axis.dot(w0);
    const denom = 1 - b * b;
    return denom < 1e-9 ? e : (e - b * d) / denom;
  }

  move(event) {
    const drag = this.drag;
    if (!drag) return;
    event.stopPropagation();
    const ray = this.scene.ray(event).ray;
    const position = drag.position.clone();
    const rotation = drag.rotation.clone();
    if (drag.mode === MOVE_AXIS) {
      position.addScaledVector(drag.axis, this.axisParam(ray, drag.position, drag.axis) - drag.startT);
    } else if (drag.mode === ROTATE_AXIS || (drag.mode === MOVE_ROTATE && event.shiftKey) ||
               drag.mode === ROTATE_3D) {
      const plane = new THREE.Plane().setFromNormalAndCoplanarPoint(drag.axis, drag.position);
      const hit = ray.intersectPlane(plane, new THREE.Vector3());
      const from = plane.projectPoint(drag.startPoint, new THREE.Vector3()).sub(drag.position);
      if (!hit || from.lengthSq() < 1e-12) return;
      const to = hit.sub(drag.position);
      const angle = Math.atan2(from.clone().cross(to).dot(drag.axis), from.dot(to));
      rotation.premultiply(new THREE.Quaternion().setFromAxisAngle(drag.axis, angle));
    } else if (drag.mode === MOVE_PLANE || drag.mode === MOVE_ROTATE || drag.mode === MOVE_3D ||
               drag.mode === MOVE_ROTATE_3D) {
      const hit = ray.intersectPlane(drag.plane, new THREE.Vector3());
      if (!hit) return;
      position.add(hit.sub(drag.startPoint));
    } else {
      return;
    }
    drag.moved = true;
    // show it there now: the root's world matrix is anchor * root
    const world = new THREE.Matrix4().compose(position, rotation, new THREE.Vector3(1, 1, 1));
    const local = drag.entry.anchor.matrixWorld.clone().invert().multiply(world);
    local.decompose(drag.entry.root.position, drag.entry.root.quaternion, drag.entry.root.scale);
    drag.hit.display.framesChanged();
    this.scene.invalidate();
    drag.pose = [position.x, position.y, position.z, rotation.x, rotation.y, rotation.z, rotation.w];
    const now = performance.now();
    if (now - this.lastSent >= 33) {
      this.lastSent = now;
      this.feedback(drag.hit, FEEDBACK.POSE_UPDATE, drag.pose);
      drag.sentPose = drag.pose;
    }
  }

  up(event) {
    const drag = this.drag;
    if (!drag) return;
    event.stopPropagation();
    this.drag = null;
    this.scene.controls.enabled = true;
    try {
      this.scene.canvas.releasePointerCapture(event.pointerId);
    } catch (err) {
      // released already
    }
    if (drag.mode === BUTTON) {
      this.feedback(drag.hit, FEEDBACK.BUTTON_CLICK);
    } else {
      if (drag.pose && drag.sentPose !== drag.pose) this.feedback(drag.hit, FEEDBACK.POSE_UPDATE, drag.pose);
      this.feedback(drag.hit, FEEDBACK.MOUSE_UP, drag.pose || matrixPose(drag.start));
    }
    // take the server's pose again once it has had the last update
    setTimeout(() => {
      if (drag.hit.display.dragging === drag.hit.name) drag.hit.display.dragging = null;
    }, 300);
  }
}

export const MODES = {NONE, MENU, BUTTON, MOVE_AXIS, MOVE_PLANE, ROTATE_AXIS, MOVE_ROTATE, MOVE_3D,
                      ROTATE_3D, MOVE_ROTATE_3D, INHERIT, FIXED, VIEW_FACING};
