"""``rosrun map_server map_server map.yaml``: serve a map file, as map_server does.

Publishes the map latched on ``map`` (nav_msgs/OccupancyGrid) and its metadata latched on
``map_metadata`` (nav_msgs/MapMetaData), serves ``static_map`` (nav_msgs/GetMap) and
``change_map`` (nav_msgs/LoadMap: load another YAML and publish it). ``~frame_id`` (default
``map``) names the frame. The node name is anonymous (``map_server_...``) unless remapped with
``__name:=``, as roscpp's map_server. The deprecated form ``map_server IMAGE RESOLUTION``
reads ``~negate``, ``~occupied_thresh`` and ``~free_thresh`` and loads a trinary map with
origin 0, after a warning.

A map that cannot be loaded ends the node with one line saying why (map_server exits too);
a failed ``change_map`` keeps the current map and answers with LoadMap's result codes
(map_server answers every failure with RESULT_UNDEFINED_FAILURE; minros says which: the file
does not exist, its YAML is invalid, or its image is).
"""

from __future__ import annotations

import math
import os
import sys
import time
from typing import Any, List

from minros.sim import mapfile
from minros.sim.grid import GridMap

USAGE = ("\nUSAGE: map_server <map.yaml>\n"
         "  map.yaml: map description file\n"
         "DEPRECATED USAGE: map_server <map> <resolution>\n"
         "  map: image file to load\n"
         "  resolution: map resolution [meters/pixel]")


def occupancy_grid(grid: GridMap, frame_id: str, stamp: Any) -> Any:
    """A nav_msgs/OccupancyGrid of ``grid`` (header and map_load_time set to ``stamp``)."""
    from nav_msgs.msg import OccupancyGrid

    msg = OccupancyGrid()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    info = msg.info
    info.map_load_time = stamp
    info.resolution = grid.resolution
    info.width, info.height = grid.width, grid.height
    ox, oy, oyaw = grid.origin
    info.origin.position.x, info.origin.position.y = ox, oy
    info.origin.orientation.z = math.sin(oyaw / 2.0)
    info.origin.orientation.w = math.cos(oyaw / 2.0)
    msg.data = grid.data.ravel()
    return msg


def _wait_for_valid_time() -> Any:
    """ros::Time::waitForValid: under simulated time, wait for the first /clock."""
    import rospy

    while not rospy.is_shutdown():
        now = rospy.Time.now()
        if not now.is_zero():
            return now
        time.sleep(0.01)
    return rospy.Time.now()


class MapServer:
    def __init__(self, grid: GridMap) -> None:
        import rospy
        from nav_msgs.msg import MapMetaData, OccupancyGrid
        from nav_msgs.srv import GetMap, LoadMap

        self.frame_id = str(rospy.get_param("~frame_id", "map"))
        self.LoadMap = LoadMap
        self.metadata_pub = rospy.Publisher("map_metadata", MapMetaData, queue_size=1, latch=True)
        self.map_pub = rospy.Publisher("map", OccupancyGrid, queue_size=1, latch=True)
        self.response = None
        self.publish(grid)
        self.services = [rospy.Service("static_map", GetMap, self._on_static_map),
                         rospy.Service("change_map", LoadMap, self._on_change_map)]

    def publish(self, grid: GridMap) -> None:
        import rospy

        stamp = _wait_for_valid_time()
        msg = occupancy_grid(grid, self.frame_id, stamp)
        rospy.loginfo(f"Read a {grid.width} X {grid.height} map @ {grid.resolution:.3f} m/cell")
        self.response = msg
        self.metadata_pub.publish(msg.info)
        self.map_pub.publish(msg)

    def _on_static_map(self, _req: Any) -> Any:
        import rospy

        rospy.loginfo("Sending map")
        return [self.response]

    def _on_change_map(self, req: Any) -> Any:
        import rospy

        response = self.LoadMap._response_class()
        try:
            grid, _desc = mapfile.load_map(req.map_url)
        except mapfile.MapError as exc:
            rospy.logerr(str(exc))
            if not os.path.exists(req.map_url):
                response.result = response.RESULT_MAP_DOES_NOT_EXIST
            elif "image" in str(exc):
                response.result = response.RESULT_INVALID_MAP_DATA
            else:
                response.result = response.RESULT_INVALID_MAP_METADATA
            return response
        self.publish(grid)
        rospy.loginfo(f"Changed map to {req.map_url}")
        response.map = self.response
        response.result = response.RESULT_SUCCESS
        return response


def main(argv: List[str] | None = None) -> int:
    import rospy

    full_argv = list(sys.argv if argv is None else argv)
    args = rospy.myargv(full_argv)[1:]
    if args and args[0] in ("-h", "--help"):
        print(USAGE.strip("\n"))
        return 0
    if len(args) not in (1, 2):
        sys.stderr.write(f"map_server: expected a map file{USAGE}\n")
        return 1
    # the map is read before the node starts, so that a bad file is one line and no node
    # (map_server registers first, then logs the error and exits)
    try:
        if len(args) == 1:
            grid, desc = mapfile.load_map(args[0])
        else:
            try:
                resolution = float(args[1])
            except ValueError:
                raise mapfile.MapError(f"resolution {args[1]!r} is not a number") from None
            grid = mapfile.load_image_map(args[0], resolution)  # thresholds re-read below
    except mapfile.MapError as exc:
        sys.stderr.write(f"map_server: {exc}\n")
        return 1
    rospy.init_node("map_server", argv=full_argv, anonymous=True)
    if len(args) == 1:
        rospy.loginfo(f'Loading map from image "{desc.image}"')
    else:
        rospy.logwarn("Using deprecated map server interface. Please switch to new interface.")
        grid = mapfile.load_image_map(
            args[0], resolution, bool(rospy.get_param("~negate", 0)),
            float(rospy.get_param("~occupied_thresh", 0.65)),
            float(rospy.get_param("~free_thresh", 0.196)))
    MapServer(grid)
    rospy.spin()
    return 0


if __name__ == "__main__":
    from minros.nodes.turtlesim import run_tool

    sys.exit(run_tool("map_server", main))
