"""``rosrun map_server map_saver [--occ N] [--free N] [-f NAME]``: save the next map received.

Subscribes to ``map`` (remap it to save another grid, e.g. ``map:=/move_base/global_costmap/costmap``),
writes ``NAME.pgm`` (254 free, 0 occupied, 205 unknown, by the ``--free``/``--occ`` thresholds
on 0..100: defaults 25 and 65) and ``NAME.yaml`` (map_server's format), then exits, as
map_server's map_saver. Arguments and their errors are map_saver's; the YAML names the image
relative to itself (see :mod:`minros.sim.mapfile`).
"""

from __future__ import annotations

import math
import sys
import threading
from typing import Any, List

from minros.sim import mapfile
from minros.sim.grid import GridMap

USAGE = ("Usage: \n"
         "  map_saver -h\n"
         "  map_saver [--occ <threshold_occupied>] [--free <threshold_free>] [-f <mapname>] "
         "[ROS remapping args]")


class UsageError(Exception):
    def __init__(self, message: str = "", status: int = 1) -> None:
        super().__init__(message)
        self.status = status


def parse_args(args: List[str]) -> tuple:
    """(mapname, occupied, free) from map_saver's arguments; UsageError as map_saver fails."""
    mapname, occupied, free = "map", mapfile.SAVER_OCCUPIED, mapfile.SAVER_FREE
    i = 0
    while i < len(args):
        arg = args[i]
        if arg == "-h":
            raise UsageError(status=0)
        if arg not in ("-f", "--occ", "--free") or i + 1 >= len(args):
            raise UsageError()
        value = args[i + 1]
        i += 2
        if arg == "-f":
            mapname = value
            continue
        try:
            number = int(value)
        except ValueError:
            raise UsageError(f"{arg} {value!r}: expected a whole number") from None
        if arg == "--occ":
            if not 1 <= number <= 100:
                raise UsageError("threshold_occupied must be between 1 and 100")
            occupied = number
        else:
            if not 0 <= number <= 100:
                raise UsageError("threshold_free must be between 0 and 100")
            free = number
    if occupied <= free:
        raise UsageError("threshold_free must be smaller than threshold_occupied")
    return mapname, occupied, free


def grid_of(msg: Any) -> GridMap:
    """The GridMap of a nav_msgs/OccupancyGrid; MapError when its size does not add up."""
    import numpy as np

    info = msg.info
    width, height = int(info.width), int(info.height)
    data = np.asarray(msg.data, dtype=np.int8)
    if width * height != data.size or width == 0 or height == 0:
        raise mapfile.MapError(f"the map's data has {data.size} cells, not width x height = "
                               f"{width} x {height}")
    q = info.origin.orientation
    yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    return GridMap(data.reshape(height, width), float(info.resolution),
                   (float(info.origin.position.x), float(info.origin.position.y), yaw))


def main(argv: List[str] | None = None) -> int:
    import rospy
    from nav_msgs.msg import OccupancyGrid

    full_argv = list(sys.argv if argv is None else argv)
    try:
        mapname, occupied, free = parse_args(rospy.myargv(full_argv)[1:])
    except UsageError as exc:
        if str(exc):
            sys.stderr.write(f"map_saver: {exc}\n")
        else:
            print(USAGE)
        return exc.status
    rospy.init_node("map_saver", argv=full_argv)
    done = threading.Event()
    outcome: List[int] = []

    def on_map(msg: Any) -> None:
        if done.is_set():
            return
        info = msg.info
        rospy.loginfo(f"Received a {info.width} X {info.height} map @ {info.resolution:.3f} m/pix")
        try:
            grid = grid_of(msg)
            rospy.loginfo(f"Writing map occupancy data to {mapname}.pgm")
            pgm, yml = mapfile.save_map(grid, mapname, occupied, free)
            rospy.loginfo(f"Writing map metadata to {yml}")
        except mapfile.MapError as exc:
            rospy.logerr(f"map_saver: {exc}")
            outcome.append(1)
        else:
            rospy.loginfo("Done")
            outcome.append(0)
        done.set()

    rospy.loginfo("Waiting for the map")
    sub = rospy.Subscriber("map", OccupancyGrid, on_map, queue_size=1)
    while not done.is_set() and not rospy.is_shutdown():
        done.wait(0.1)
    sub.unregister()
    rospy.signal_shutdown("map saved")
    return outcome[0] if outcome else 0


if __name__ == "__main__":
    from minros.nodes.turtlesim import run_tool

    sys.exit(run_tool("map_saver", main))
