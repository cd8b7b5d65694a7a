"""``rosrun turtlesim turtlesim_node``: the ROS face of :class:`minros.nodes.turtlesim.sim.TurtleFrame`.

Interfaces as in noetic's turtlesim: node ``turtlesim``; services ``clear``, ``reset``, ``spawn``,
``kill`` in the node's namespace; per turtle ``<name>/cmd_vel`` (in), ``<name>/pose`` and
``<name>/color_sensor`` (out, every 16 ms tick), ``<name>/set_pen``, ``<name>/teleport_absolute``,
``<name>/teleport_relative``; private parameters ``~background_{r,g,b}`` set when absent and read
on clear/reset.

Extra options (not in the C++ node): ``--headless`` (also MINROS_HEADLESS=1, or automatically
without a display) and ``--snapshot FILE.png`` (or the ``~snapshot`` parameter) which writes the
window contents every ``--snapshot-period`` seconds and at shutdown.
"""

from __future__ import annotations

import argparse
import os
import sys
import threading
import time
from typing import Any, Callable, Dict, List, Tuple

from minros.nodes.turtlesim import sim

_BACKGROUND_PARAMS = (("background_r", sim.DEFAULT_BACKGROUND[0]),
                      ("background_g", sim.DEFAULT_BACKGROUND[1]),
                      ("background_b", sim.DEFAULT_BACKGROUND[2]))


#: Minimum time between two window redraws (the simulation itself still ticks every 16 ms).
_REDRAW_INTERVAL = 1 / 30


def _cpp_service_class():
    """A rospy Service whose handler may return False, answered like a roscpp callback
    returning false: ``ok=0`` with an empty error text (what clients of the real turtlesim see
    for an existing spawn name or an unknown kill name)."""
    import rospy
    from minros.wire import tcpros

    class CppStyleService(rospy.Service):
        def __init__(self, name: str, service_class: type, handler: Callable[[Any], Any]) -> None:
            local = threading.local()  # connections are served in parallel threads

            def wrapped(request: Any) -> Any:
                result = handler(request)
                local.refused = result is False
                return service_class._response_class() if result is False else result

            super().__init__(name, service_class, wrapped)
            self._local = local

        def _respond(self, request: Any) -> bytes:
            self._local.refused = False
            reply = super()._respond(request)
            return tcpros.encode_service_error("") if self._local.refused else reply

    return CppStyleService


class _TurtleInterfaces:
    """Topics and services of one turtle (the C++ Turtle's NodeHandle(name) members)."""

    def __init__(self, node: TurtlesimNode, name: str) -> None:
        import rospy
        from geometry_msgs.msg import Twist
        from turtlesim.msg import Color, Pose
        from turtlesim.srv import SetPen, TeleportAbsolute, TeleportRelative

        self.node = node
        self.name = name
        # NodeHandle(name) resolves (and remaps) the namespace, then each topic inside it.
        ns = rospy.resolve_name(name)

        def sub(base: str) -> str:
            return rospy.resolve_name(ns.rstrip("/") + "/" + base)

        service = node.service_class
        self.pose_msg, self.color_msg = Pose, Color
        self.pose_pub = rospy.Publisher(sub("pose"), Pose, queue_size=1)
        self.color_pub = rospy.Publisher(sub("color_sensor"), Color, queue_size=1)
        self.cmd_sub = rospy.Subscriber(sub("cmd_vel"), Twist, self._on_cmd_vel, queue_size=1)
        self.services = [
            service(sub("set_pen"), SetPen, self._on_set_pen),
            service(sub("teleport_relative"), TeleportRelative, self._on_teleport_relative),
            service(sub("teleport_absolute"), TeleportAbsolute, self._on_teleport_absolute),
        ]

    def _with_turtle(self, action: Callable[[sim.Turtle], None]) -> bool:
        with self.node.lock:
            turtle = self.node.world.turtles.get(self.name)
            if turtle is None:
                return False
            action(turtle)
            return True

    def _on_cmd_vel(self, msg: Any) -> None:
        import rospy

        now = self.node.world.clock()
        try:
            self._with_turtle(
                lambda t: t.command_velocity(msg.linear.x, msg.linear.y, msg.angular.z, now))
        except sim.NonFiniteError as exc:
            rospy.logwarn_throttle(5.0, str(exc))

    def _service(self, action: Callable[[sim.Turtle], None]) -> Any:
        import rospy

        try:
            ok = self._with_turtle(action)
        except sim.NonFiniteError as exc:
            raise rospy.ServiceException(str(exc)) from None
        return [] if ok else False

    def _on_set_pen(self, req: Any) -> Any:
        return self._service(lambda t: t.set_pen(req.r, req.g, req.b, req.width, req.off))

    def _on_teleport_relative(self, req: Any) -> Any:
        return self._service(lambda t: t.teleport_relative(req.linear, req.angular))

    def _on_teleport_absolute(self, req: Any) -> Any:
        return self._service(lambda t: t.teleport_absolute(req.x, req.y, req.theta))

    def publish(self, update: sim.TurtleUpdate) -> None:
        self.pose_pub.publish(self.pose_msg(*update.pose))
        self.color_pub.publish(self.color_msg(*update.color))

    def shutdown(self) -> None:
        """Unregister everything (a killed turtle disappears from the master)."""
        for service in self.services:
            service.shutdown("turtle killed")
        self.cmd_sub.unregister()
        self.pose_pub.unregister()
        self.color_pub.unregister()


class TurtlesimNode:
    """The node: a TurtleFrame, its lock, the node-level services and per-turtle interfaces."""

    def __init__(self) -> None:
        import rospy
        from std_srvs.srv import Empty
        from turtlesim.srv import Kill, Spawn

        self.lock = threading.RLock()  # the world: ticks vs. callbacks
        self.admin = threading.Lock()  # spawn/kill/reset one at a time (they register topics)
        self.service_class = _cpp_service_class()
        self.interfaces: Dict[str, _TurtleInterfaces] = {}
        self.dirty = True
        for key, default in _BACKGROUND_PARAMS:
            if not rospy.has_param("~" + key):
                rospy.set_param("~" + key, default)
        self.world = sim.TurtleFrame(background=self.background(), info=rospy.loginfo,
                                     warn=rospy.logwarn, error=rospy.logerr, spawn_first=False)
        self.services = [
            self.service_class("clear", Empty, self._on_clear),
            self.service_class("reset", Empty, self._on_reset),
            self.service_class("spawn", Spawn, self._on_spawn),
            self.service_class("kill", Kill, self._on_kill),
        ]
        rospy.loginfo(f"Starting turtlesim with node name {rospy.get_name()}")
        with self.admin:
            self._spawn("", sim.CENTER, sim.CENTER, 0.0)

    @staticmethod
    def background() -> Tuple[int, int, int]:
        """``~background_{r,g,b}`` (ints; anything else counts as absent, like NodeHandle::param)."""
        import rospy

        values = []
        for key, default in _BACKGROUND_PARAMS:
            try:
                value = rospy.get_param("~" + key, default)
            except Exception:  # master gone: keep the default rather than crash the tick loop
                value = default
            if isinstance(value, bool) or not isinstance(value, int):
                value = default
            values.append(value & 0xFF)
        return values[0], values[1], values[2]

    # -- services -----------------------------------------------------------------------------

    def _spawn(self, name: str, x: float, y: float, theta: float) -> str:
        import rospy

        try:
            sim.check_finite("spawn", x=x, y=y, theta=theta)
        except sim.NonFiniteError as exc:
            raise rospy.ServiceException(str(exc)) from None
        with self.lock:
            real = self.world.next_name(name)
        if not real:
            rospy.logerr(f"A turtled named [{name}] already exists")
            return ""
        if not sim.is_legal_turtle_name(real):
            # roscpp would throw InvalidNameException from NodeHandle(name) and die; refuse instead.
            text = f"Cannot spawn turtle [{real}]: not a legal ROS name"
            rospy.logerr(text)
            raise rospy.ServiceException(text)
        self.interfaces[real] = _TurtleInterfaces(self, real)
        with self.lock:
            self.world.add_turtle(real, x, y, theta)
            self.dirty = True
        return real

    def _on_spawn(self, req: Any) -> Any:
        with self.admin:
            name = self._spawn(req.name, req.x, req.y, req.theta)
        return name if name else False

    def _on_kill(self, req: Any) -> Any:
        with self.admin:
            with self.lock:
                ok = self.world.kill(req.name)
                self.dirty = True
            if not ok:
                return False
            iface = self.interfaces.pop(req.name, None)
        if iface is not None:
            iface.shutdown()
        return []

    def _on_clear(self, req: Any) -> Any:
        import rospy

        rospy.loginfo("Clearing turtlesim.")
        background = self.background()
        with self.lock:
            self.world.clear(background)
            self.dirty = True
        return []

    def _on_reset(self, req: Any) -> Any:
        import rospy

        rospy.loginfo("Resetting turtlesim.")
        with self.admin:
            old = list(self.interfaces.values())
            self.interfaces.clear()
            with self.lock:
                self.world.turtles.clear()
                self.world.id_counter = 0
            for iface in old:
                iface.shutdown()
            self._spawn("", sim.CENTER, sim.CENTER, 0.0)
        background = self.background()
        with self.lock:
            self.world.clear(background)
            self.dirty = True
        return []

    # -- the timer ------------------------------------------------------------------------------

    def step(self) -> None:
        """One tick: update every turtle, then publish their pose and colour."""
        with self.lock:
            updates, modified = self.world.tick()
            self.dirty = self.dirty or modified
        for update in updates:
            iface = self.interfaces.get(update.name)
            if iface is not None:
                iface.publish(update)

    def render(self) -> Any:
        with self.lock:
            self.dirty = False
            return self.world.render()


# -- display ------------------------------------------------------------------------------------


class _TkDisplay:
    """A 500x500 Tk window showing the rendered frame; created only when a display exists."""

    def __init__(self, title: str) -> None:
        import tkinter

        self.tk = tkinter
        self.root = tkinter.Tk()
        self.root.title(title)
        self.root.resizable(False, False)
        self.closed = False
        self.root.protocol("WM_DELETE_WINDOW", self._close)
        self.photo = tkinter.PhotoImage(width=sim.CANVAS_PIXELS, height=sim.CANVAS_PIXELS)
        self.label = tkinter.Label(self.root, image=self.photo, borderwidth=0)
        self.label.pack()

    def _close(self) -> None:
        self.closed = True

    def show(self, frame: Any) -> None:
        header = b"P6 %d %d 255\n" % (frame.shape[1], frame.shape[0])
        self.photo = self.tk.PhotoImage(data=header + frame.tobytes(), format="PPM")
        self.label.configure(image=self.photo)

    def pump(self) -> bool:
        """Process window events; False once the window was closed."""
        self.root.update()
        return not self.closed

    def destroy(self) -> None:
        try:
            self.root.destroy()
        except Exception:  # already gone with the X connection
            pass


def _open_display(headless: bool, title: str) -> Tuple[_TkDisplay | None, str]:
    """The window, or None and why there is none."""
    if headless:
        return None, "headless mode requested"
    if os.environ.get("MINROS_HEADLESS", "") not in ("", "0"):
        return None, "MINROS_HEADLESS is set"
    if not os.environ.get("DISPLAY") and sys.platform.startswith("linux"):
        return None, "no DISPLAY"
    try:
        return _TkDisplay(title), ""
    except Exception as exc:  # no tkinter, or the display refused us
        return None, f"cannot open a window ({(str(exc).splitlines() or [type(exc).__name__])[0]})"


def write_snapshot(path: str, frame_rgb: Any) -> None:
    """Write an RGB frame as an image file atomically (readers never see half a PNG)."""
    import cv2

    ext = os.path.splitext(path)[1] or ".png"
    tmp = f"{path}.tmp{os.getpid()}{ext}"
    if not cv2.imwrite(tmp, frame_rgb[:, :, ::-1]):
        raise OSError(f"cannot write image {path}")
    os.replace(tmp, path)


def _parse_args(argv: List[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        prog="turtlesim_node",
        description="Turtle simulator (minros re-implementation of ros_tutorials/turtlesim).")
    parser.add_argument("--headless", action="store_true",
                        help="run without a window (also MINROS_HEADLESS=1, or no DISPLAY)")
    parser.add_argument("--snapshot", metavar="FILE.png",
                        help="write the window contents to FILE.png periodically and at shutdown "
                             "(or set the ~snapshot parameter)")
    parser.add_argument("--snapshot-period", type=float, default=1.0, metavar="SEC",
                        help="seconds between snapshots (default 1.0; 0 = only at shutdown)")
    return parser.parse_args(argv)


def main(argv: List[str] | None = None) -> int:
    import rospy

    full_argv = list(sys.argv if argv is None else argv)
    args = _parse_args(rospy.myargv(full_argv)[1:])
    rospy.init_node("turtlesim", argv=full_argv)
    node = TurtlesimNode()

    snapshot = args.snapshot or rospy.get_param("~snapshot", "") or None
    display, reason = _open_display(args.headless, "TurtleSim")
    if display is None:
        rospy.loginfo(f"turtlesim runs without a window: {reason}")

    period = sim.UPDATE_INTERVAL_MS / 1000.0
    next_tick = next_redraw = time.monotonic()
    next_snapshot = next_tick + args.snapshot_period if snapshot and args.snapshot_period > 0 else None
    try:
        while not rospy.is_shutdown():
            try:
                node.step()
            except Exception as exc:  # e.g. a publisher closed by a shutdown racing this tick
                if rospy.is_shutdown():
                    break
                rospy.logerr_throttle(5.0, f"turtlesim: update failed: {exc}")
            if display is not None:
                try:
                    now = time.monotonic()
                    if node.dirty and now >= next_redraw:  # ~30 fps is plenty for a window
                        display.show(node.render())
                        next_redraw = now + _REDRAW_INTERVAL
                    alive = display.pump()
                except Exception as exc:  # the display went away (X server gone)
                    rospy.logwarn(f"turtlesim: window lost ({exc}); continuing without it")
                    display, alive = None, True
                if not alive:
                    rospy.signal_shutdown("window closed")
                    break
            if next_snapshot is not None and time.monotonic() >= next_snapshot:
                write_snapshot(snapshot, node.render())
                next_snapshot += args.snapshot_period
            next_tick += period
            delay = next_tick - time.monotonic()
            if delay < -0.25:  # fell far behind (suspended?): do not burst to catch up
                next_tick = time.monotonic()
            elif delay > 0:
                _wait(delay)
    except KeyboardInterrupt:
        rospy.signal_shutdown("keyboard interrupt")
    finally:
        if snapshot:
            try:
                write_snapshot(snapshot, node.render())
            except Exception as exc:
                sys.stderr.write(f"turtlesim: cannot write snapshot: {exc}\n")
        if display is not None:
            display.destroy()
    return 0


def _wait(delay: float) -> None:
    from minros import node as _node

    _node.wait_for_shutdown(delay)


if __name__ == "__main__":
    from minros.nodes.turtlesim import run_tool

    sys.exit(run_tool("turtlesim_node", main))
