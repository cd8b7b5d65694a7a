// Rviz's "2D Pose Estimate" and "2D Nav Goal": press on the ground where the robot is (or
// should go), drag towards where it faces, release. The pose is published in the fixed frame:
// geometry_msgs/PoseWithCovarianceStamped on /initialpose (Rviz's covariance: 0.5 m in x and y,
// pi/12 in yaw) or geometry_msgs/PoseStamped on /move_base_simple/goal (each topic can be
// changed in the view's panel, as Rviz's tool properties, e.g. for a robot under a namespace).
// As in Rviz, the tool goes back to Interact after one use.

import {arrow, dispose} from "./shapes.js";

export const TOOLS = {
  pose_estimate: {title: "2D Pose Estimate", topic: "/initialpose",
                  type: "geometry_msgs/PoseWithCovarianceStamped", color: [0.2, 1, 0.2, 1]},
  nav_goal: {title: "2D Nav Goal", topic: "/move_base_simple/goal",
             type: "geometry_msgs/PoseStamped", color: [1, 0.2, 0.8, 1]},
};

/** The message a tool publishes for a pose on the ground of frame `fixed`. */
export function toolMessage(tool, fixed, x, y, yaw) {
  const pose = {position: {x, y, z: 0}, orientation: {x: 0, y: 0, z: Math.sin(yaw / 2), w: Math.cos(yaw / 2)}};
  const header = {frame_id: fixed};  // stamped now by the server, as rosbridge does
  if (tool === "nav_goal") return {header, pose};
  const covariance = new Array(36).fill(0);
  covariance[0] = 0.25;
  covariance[7] = 0.25;
  covariance[35] = (Math.PI / 12) ** 2;
  return {header, pose: {pose, covariance}};
}

export class GroundTool {
  constructor(view) {
    this.view = view;
    this.scene = view.scene3d;
    this.start = null;
    this.preview = null;
    const canvas = this.scene.canvas;
    canvas.addEventListener("pointerdown", (e) => this.down(e), true);
    canvas.addEventListener("pointermove", (e) => this.move(e), true);
    canvas.addEventListener("pointerup", (e) => this.up(e), true);
  }

  get active() {
    return TOOLS[this.view.tool] ? this.view.tool : null;
  }

  down(event) {
    if (!this.active || event.button !== 0) return;
    const point = this.scene.ground(event);
    if (!point) return;
    event.stopImmediatePropagation();
    event.preventDefault();
    this.scene.canvas.setPointerCapture(event.pointerId);
    this.scene.controls.enabled = false;
    this.start = point;
    this.yaw = 0;
    this.draw();
  }

  move(event) {
    if (!this.start) return;
    event.stopImmediatePropagation();
    const point = this.scene.ground(event);
    if (point && point.distanceTo(this.start) > 1e-3) {
      this.yaw = Math.atan2(point.y - this.start.y, point.x - this.start.x);
      this.draw();
    }
  }

  draw() {
    dispose(this.preview);
    this.preview = arrow(1.0, 0.05, 0.15, 0.25, TOOLS[this.active].color);
    this.preview.position.copy(this.start);
    this.preview.rotation.z = this.yaw;
    this.scene.scene.add(this.preview);
    this.scene.invalidate();
  }

  up(event) {
    if (!this.start) return;
    event.stopImmediatePropagation();
    const tool = this.active;
    const {x, y} = this.start;
    this.start = null;
    this.scene.controls.enabled = true;
    dispose(this.preview);
    this.preview = null;
    this.scene.invalidate();
    const spec = TOOLS[tool];
    const topic = this.view.toolTopic(tool);
    const msg = toolMessage(tool, this.scene.fixed, x, y, this.yaw);
    this.view.app.conn.publish(topic, spec.type, msg);
    this.view.published.push({tool, topic, x, y, yaw: this.yaw, frame: this.scene.fixed});
    this.view.setTool("interact");
    this.view.note(`${spec.title}: published x ${x.toFixed(2)}, y ${y.toFixed(2)}, yaw ` +
                   `${(this.yaw * 180 / Math.PI).toFixed(0)}° in ${this.scene.fixed} on ${topic}`);
  }
}
