"""The turtlesim simulation, free of ROS: turtles, the 16 ms update step, the pen and the path image.

The numbers follow ros_tutorials/turtlesim (noetic) so that a script tuned against the real
simulator behaves the same here: 45 px per metre on a 500x500 px canvas (11.088889 m square),
a fixed dt of 0.016 s per tick, a 1 s wall-clock timeout on velocity commands, orientation
wrapped to [-pi, pi) with the C++ constant ``PI = 3.14159265``, positions kept in Qt
coordinates (y pointing down) and clamped to the canvas with the original warning text.

The ROS node (:mod:`minros.nodes.turtlesim.turtlesim_node`) is a thin layer around
:class:`TurtleFrame`; everything here can be driven tick by tick from a unit test.
"""

from __future__ import annotations

import math
import random
import re
import time
from dataclasses import dataclass, field
from typing import Callable, Dict, List, NamedTuple, Tuple

import numpy as np

#: turtle.cpp's ``#define PI 3.14159265`` (not math.pi: the wrap uses this exact value).
PI = 3.14159265
#: Canvas size in pixels (TurtleFrame::setFixedSize(500, 500)).
CANVAS_PIXELS = 500
#: Height in pixels of the turtle images, which turtlesim uses as "one metre".
METER = 45
#: QTimer interval in ms; dt is derived from it (0.001 * interval), never measured.
UPDATE_INTERVAL_MS = 16
DT = 0.001 * UPDATE_INTERVAL_MS
#: Velocity commands older than this (wall time) are dropped.
COMMAND_TIMEOUT = 1.0
#: width_in_meters_ / height_in_meters_ are C++ ``float``: (500 - 1) / 45 in float32.
CANVAS_METERS = float(np.float32(CANVAS_PIXELS - 1) / np.float32(METER))
#: Where turtle1 is spawned: width_in_meters_ / 2.0 (exact half of the float32).
CENTER = CANVAS_METERS / 2.0

DEFAULT_BACKGROUND: Tuple[int, int, int] = (69, 86, 255)
DEFAULT_PEN_COLOR: Tuple[int, int, int] = (179, 184, 255)
DEFAULT_PEN_WIDTH = 3
#: Width of ``QPen(QColor)``, which set_pen uses when the request's width is 0.
QT_DEFAULT_PEN_WIDTH = 1

WALL_WARNING = "Oh no! I hit the wall! (Clamping from [x=%f, y=%f])"

# A turtle name becomes a ROS namespace (NodeHandle(name)); roscpp would throw on anything else.
_LEGAL_NAME = re.compile(r"^[~/]?[A-Za-z][\w/]*$", re.ASCII)


class NonFiniteError(ValueError):
    """A command or request carried NaN or infinity (C++ turtlesim would lose the turtle)."""


def check_finite(what: str, **values: float) -> None:
    """Raise :class:`NonFiniteError` naming the offending fields if any value is NaN/inf."""
    bad = [f"{k}={v}" for k, v in values.items() if not math.isfinite(v)]
    if bad:
        raise NonFiniteError(f"{what}: non-finite value ({', '.join(bad)}) ignored")


def _f32(value: float) -> float:
    """Round a Python float to the nearest float32, as a C++ ``float`` member would store it."""
    return float(np.float32(value))


def is_legal_turtle_name(name: str) -> bool:
    """Whether ``name`` is usable as the turtle's namespace (a legal ROS graph name)."""
    return bool(_LEGAL_NAME.match(name)) and "//" not in name and not name.endswith("/")


class PoseState(NamedTuple):
    """What ``<turtle>/pose`` carries (world coordinates, y up)."""

    x: float
    y: float
    theta: float
    linear_velocity: float
    angular_velocity: float


class TurtleUpdate(NamedTuple):
    """Result of one turtle's tick: the pose and colour_sensor values to publish."""

    name: str
    pose: PoseState
    color: Tuple[int, int, int]


@dataclass
class _Teleport:
    relative: bool
    x: float = 0.0
    y: float = 0.0
    theta: float = 0.0
    linear: float = 0.0


@dataclass
class Turtle:
    """One turtle: position in Qt coordinates (``y_qt`` grows downwards), velocities and pen."""

    name: str
    x: float
    y_qt: float
    orient: float
    lin_vel_x: float = 0.0
    lin_vel_y: float = 0.0
    ang_vel: float = 0.0
    last_command_time: float = 0.0
    pen_on: bool = True
    pen_color: Tuple[int, int, int] = DEFAULT_PEN_COLOR
    pen_width: int = DEFAULT_PEN_WIDTH
    teleports: List[_Teleport] = field(default_factory=list)
    #: Which look the turtle gets in the window (turtlesim picks a random turtle image).
    icon: int = 0

    # -- what the ROS callbacks do (they only record; the tick applies) ----------------------

    def command_velocity(self, linear_x: float, linear_y: float, angular_z: float, now: float) -> None:
        """cmd_vel callback: store the velocities and the (wall) time they arrived."""
        check_finite(f"[{self.name}] cmd_vel", linear_x=linear_x, linear_y=linear_y,
                     angular_z=angular_z)
        self.last_command_time = now
        self.lin_vel_x = linear_x
        self.lin_vel_y = linear_y
        self.ang_vel = angular_z

    def set_pen(self, r: int, g: int, b: int, width: int, off: int) -> None:
        """set_pen service: ``off`` only switches the pen off, keeping colour and width."""
        self.pen_on = not off
        if off:
            return
        self.pen_color = (int(r), int(g), int(b))
        self.pen_width = int(width) if width != 0 else QT_DEFAULT_PEN_WIDTH

    def teleport_absolute(self, x: float, y: float, theta: float) -> None:
        """teleport_absolute service: queued, applied at the start of the next tick."""
        check_finite(f"[{self.name}] teleport_absolute", x=x, y=y, theta=theta)
        self.teleports.append(_Teleport(relative=False, x=x, y=y, theta=theta))

    def teleport_relative(self, linear: float, angular: float) -> None:
        """teleport_relative service: queued, applied at the start of the next tick."""
        check_finite(f"[{self.name}] teleport_relative", linear=linear, angular=angular)
        self.teleports.append(_Teleport(relative=True, theta=angular, linear=linear))

    # -- the tick --------------------------------------------------------------------------

    def pose(self, canvas_height: float = CANVAS_METERS) -> PoseState:
        return PoseState(self.x, canvas_height - self.y_qt, self.orient,
                         math.sqrt(self.lin_vel_x ** 2 + self.lin_vel_y ** 2), self.ang_vel)

    def update(self, dt: float, path: PathImage, canvas_width: float, canvas_height: float,
               now: float, warn: Callable[[str], None]) -> Tuple[TurtleUpdate, bool]:
        """Turtle::update: teleports, timeout, integrate, clamp, sense, draw.

        Returns the values to publish and whether anything visible changed.
        """
        modified = False
        old_orient = self.orient
        for req in self.teleports:
            old = (self.x, self.y_qt)
            if req.relative:
                self.orient += req.theta
                self.x += math.cos(self.orient) * req.linear
                self.y_qt += -math.sin(self.orient) * req.linear
            else:
                self.x = req.x
                self.y_qt = max(0.0, canvas_height - req.y)
                self.orient = req.theta
            if self.pen_on:
                path.draw_line(old, (self.x, self.y_qt), self.pen_color, self.pen_width)
            modified = True
        self.teleports = []

        if now - self.last_command_time > COMMAND_TIMEOUT:
            self.lin_vel_x = self.lin_vel_y = self.ang_vel = 0.0

        old = (self.x, self.y_qt)
        self.orient = self.orient + self.ang_vel * dt
        self.orient -= 2 * PI * math.floor((self.orient + PI) / (2 * PI))
        cos_o, sin_o = math.cos(self.orient), math.sin(self.orient)
        self.x += cos_o * self.lin_vel_x * dt - sin_o * self.lin_vel_y * dt
        self.y_qt -= cos_o * self.lin_vel_y * dt + sin_o * self.lin_vel_x * dt

        if self.x < 0 or self.x > canvas_width or self.y_qt < 0 or self.y_qt > canvas_height:
            warn(WALL_WARNING % (self.x, self.y_qt))
        self.x = min(max(self.x, 0.0), canvas_width)
        self.y_qt = min(max(self.y_qt, 0.0), canvas_height)

        result = TurtleUpdate(self.name, self.pose(canvas_height), path.pixel_at(self.x, self.y_qt))

        if self.orient != old_orient:
            modified = True
        if (self.x, self.y_qt) != old:
            if self.pen_on:
                path.draw_line(old, (self.x, self.y_qt), self.pen_color, self.pen_width)
            modified = True
        return result, modified


def _qround(value: float) -> int:
    """qRound: halves rounded away from zero."""
    return int(math.floor(value + 0.5)) if value >= 0 else int(math.ceil(value - 0.5))


class PathImage:
    """The 500x500 RGB canvas the pens draw on (turtlesim's ``path_image_``)."""

    def __init__(self, size: int = CANVAS_PIXELS, background: Tuple[int, int, int] = DEFAULT_BACKGROUND):
        self.size = size
        self.pixels = np.empty((size, size, 3), dtype=np.uint8)
        self.fill(background)

    def fill(self, color: Tuple[int, int, int]) -> None:
        self.pixels[:, :] = np.asarray(color, dtype=np.uint8)

    def pixel_at(self, x_m: float, y_qt_m: float) -> Tuple[int, int, int]:
        """The colour under a turtle: ``path_image.pixel((pos * meter).toPoint())``."""
        col = min(max(_qround(x_m * METER), 0), self.size - 1)
        row = min(max(_qround(y_qt_m * METER), 0), self.size - 1)
        r, g, b = self.pixels[row, col]
        return int(r), int(g), int(b)

    def draw_line(self, a_m: Tuple[float, float], b_m: Tuple[float, float],
                  color: Tuple[int, int, int], width: int) -> None:
        """A pen stroke between two positions in metres (Qt coordinates), not antialiased."""
        import cv2  # heavy import, only once something is drawn

        shift = 4  # sub-pixel endpoints, as QPainter takes floating-point coordinates
        scale = METER * (1 << shift)
        p1 = (int(round(a_m[0] * scale)), int(round(a_m[1] * scale)))
        p2 = (int(round(b_m[0] * scale)), int(round(b_m[1] * scale)))
        cv2.line(self.pixels, p1, p2, tuple(int(c) for c in color), max(1, int(width)),
                 cv2.LINE_8, shift)


class TurtleFrame:
    """TurtleFrame without Qt: the set of turtles, the path image and the services' logic.

    ``clock`` is the wall clock used for the cmd_vel timeout; ``warn``/``info``/``error``
    receive the log lines the C++ node prints with ROS_WARN/ROS_INFO/ROS_ERROR.
    """

    def __init__(self, background: Tuple[int, int, int] = DEFAULT_BACKGROUND,
                 clock: Callable[[], float] = time.monotonic,
                 info: Callable[[str], None] | None = None,
                 warn: Callable[[str], None] | None = None,
                 error: Callable[[str], None] | None = None,
                 spawn_first: bool = True) -> None:
        self.clock = clock
        self.info = info or (lambda text: None)
        self.warn = warn or (lambda text: None)
        self.error = error or (lambda text: None)
        self.width_m = CANVAS_METERS
        self.height_m = CANVAS_METERS
        self.path = PathImage(background=background)
        self.turtles: Dict[str, Turtle] = {}
        self.id_counter = 0
        self.frame_count = 0
        self._started = False
        self._icons = random.Random()
        if spawn_first:
            self.spawn("", CENTER, CENTER, 0.0)

    # -- services ----------------------------------------------------------------------------

    def next_name(self, name: str) -> str:
        """The name ``spawn(name)`` would use, '' if taken; advances the counter for ''."""
        if name:
            return "" if name in self.turtles else name
        while True:
            self.id_counter += 1
            candidate = f"turtle{self.id_counter}"
            if candidate not in self.turtles:
                return candidate

    def add_turtle(self, name: str, x: float, y: float, theta: float) -> Turtle:
        """Insert a turtle whose name was chosen by :meth:`next_name`, and log it."""
        check_finite("spawn", x=x, y=y, theta=theta)
        x, y, theta = _f32(x), _f32(y), _f32(theta)  # spawnTurtle takes C++ floats
        turtle = Turtle(name, x, _f32(self.height_m - y), theta, last_command_time=self.clock(),
                        icon=self._icons.randrange(len(ICON_COLORS)))
        self.turtles[name] = turtle
        self.info(f"Spawning turtle [{name}] at x=[{x:f}], y=[{y:f}], theta=[{theta:f}]")
        return turtle

    def spawn(self, name: str, x: float, y: float, theta: float) -> str:
        """spawn service: the turtle's name, or '' when ``name`` already exists (logged)."""
        check_finite("spawn", x=x, y=y, theta=theta)
        real = self.next_name(name)
        if not real:
            self.error(f"A turtled named [{name}] already exists")
            return ""
        self.add_turtle(real, x, y, theta)
        return real

    def kill(self, name: str) -> bool:
        """kill service: False (and an error log) for an unknown turtle."""
        if name not in self.turtles:
            self.error(f"Tried to kill turtle [{name}], which does not exist")
            return False
        del self.turtles[name]
        return True

    def clear(self, background: Tuple[int, int, int] = DEFAULT_BACKGROUND) -> None:
        """clear service: repaint the canvas with the background colour (from the params)."""
        self.path.fill(background)

    def reset(self, background: Tuple[int, int, int] = DEFAULT_BACKGROUND) -> str:
        """reset service: drop all turtles, restart the counter, spawn turtle1, clear."""
        self.turtles.clear()
        self.id_counter = 0
        name = self.spawn("", CENTER, CENTER, 0.0)
        self.clear(background)
        return name

    # -- the timer ---------------------------------------------------------------------------

    def tick(self) -> Tuple[List[TurtleUpdate], bool]:
        """One 16 ms timer tick (updateTurtles). The first tick only starts the clock."""
        if not self._started:
            self._started = True
            return [], False
        now = self.clock()
        updates = []
        modified = False
        for name in sorted(self.turtles):  # std::map order
            result, changed = self.turtles[name].update(DT, self.path, self.width_m, self.height_m,
                                                       now, self.warn)
            updates.append(result)
            modified = modified or changed
        self.frame_count += 1
        return updates, modified

    # -- drawing -----------------------------------------------------------------------------

    def render(self) -> np.ndarray:
        """The window contents (RGB): path image with a turtle icon per turtle."""
        frame = self.path.pixels.copy()
        for name in sorted(self.turtles):
            t = self.turtles[name]
            draw_turtle_icon(frame, t.x * METER, t.y_qt * METER, t.orient, ICON_COLORS[t.icon])
        return frame


def _rotate(points: np.ndarray, angle: float) -> np.ndarray:
    """Rotate icon points (x right, y up) by ``angle`` and flip to image rows (y down)."""
    c, s = math.cos(angle), math.sin(angle)
    x = points[:, 0] * c - points[:, 1] * s
    y = points[:, 0] * s + points[:, 1] * c
    return np.stack([x, -y], axis=1)


# A small top-down turtle drawn in the icon's own frame (pixels, heading along +x).
_SHELL = np.array([[13, 0], [9, 9], [0, 12], [-9, 9], [-13, 0], [-9, -9], [0, -12], [9, -9]], float)
_HEAD = np.array([[13, -4], [20, -4], [22, 0], [20, 4], [13, 4]], float)
_LEGS = [np.array([[dx - 3, dy - 3], [dx + 3, dy - 3], [dx + 3, dy + 3], [dx - 3, dy + 3]], float)
         for dx, dy in ((7, 11), (7, -11), (-7, 11), (-7, -11))]


#: (shell, skin, shell pattern) RGB per icon.
ICON_COLORS = [
    ((34, 110, 34), (96, 160, 64), (150, 200, 90)),
    ((120, 80, 40), (200, 170, 110), (230, 200, 140)),
    ((40, 90, 120), (110, 170, 150), (160, 210, 220)),
    ((140, 40, 60), (210, 150, 110), (240, 170, 170)),
    ((90, 90, 30), (170, 170, 80), (220, 220, 120)),
]


def draw_turtle_icon(frame: np.ndarray, cx: float, cy: float, orient: float,
                     colors: Tuple[Tuple[int, int, int], ...] = ICON_COLORS[0]) -> None:
    """Draw a turtle centred at pixel (cx, cy) heading ``orient`` (radians, CCW from +x)."""
    import cv2

    shift = 4
    centre = np.array([cx, cy])

    def poly(points: np.ndarray) -> np.ndarray:
        return np.round((_rotate(points, orient) + centre) * (1 << shift)).astype(np.int32)

    shell, skin, pattern = colors
    for leg in _LEGS:
        cv2.fillPoly(frame, [poly(leg)], skin, cv2.LINE_AA, shift)
    cv2.fillPoly(frame, [poly(_HEAD)], skin, cv2.LINE_AA, shift)
    cv2.fillPoly(frame, [poly(_SHELL)], shell, cv2.LINE_AA, shift)
    cv2.polylines(frame, [poly(_SHELL * 0.55)], True, pattern, 1, cv2.LINE_AA, shift)
