"""ROS 2 recordings (rosbag2) for rosbag: reading them as ROS 1, and writing them.

* :mod:`.storage`: which paths are rosbag2 recordings, opening them (rosbags reads the MCAP and
  SQLite storage files), one-line errors for damaged ones;
* :mod:`.reader`: a recording seen as a ROS 1 bag (types by ros1_bridge's rules, CDR -> ROS 1
  bytes as messages are read), the reader ``rosbag info``/``play``, ``rostopic echo -b`` and
  the ``Bag`` API use;
* :mod:`.writer`: a new rosbag2 directory (rosbags' storage writers, the distro's metadata);
* :mod:`.msgdef`: the ``ros2msg`` definitions rosbag2 stores with each type.

``rosbag convert`` (:mod:`minros.bag.convert`) joins them with the ROS 1 readers and writers.
"""
