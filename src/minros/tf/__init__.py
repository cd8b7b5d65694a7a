"""tf and tf2 for minros, in pure Python.

ROS 1's tf2 core is C++ (tf2_py); here every piece is Python:

* ``core``: tf2's BufferCore (per-frame time caches, latest common time, lerp/slerp,
  static frames, tf2's exceptions and insert checks); pure, no sockets or threads;
* ``buffer``, ``listener``, ``broadcaster``: the tf2_ros API (Buffer, TransformListener,
  TransformBroadcaster, StaticTransformBroadcaster);
* ``geometry``: tf2_geometry_msgs (``buffer.transform(point_stamped, frame)``);
* ``tf1``: ROS 1's first API (tf.TransformListener, tf.TransformBroadcaster);
* ``transformations``: tf.transformations, written from the mathematics;
* tools run with ``python -m``: ``static_transform_publisher`` (tf2_ros's),
  ``tf_static_transform_publisher`` (tf's periodic one), ``tf_echo``, ``tf_monitor``,
  ``view_frames`` (the turtlesim tf tutorial's nodes are minros.nodes.turtle_tf).

The ROS-named packages ``tf``, ``tf2_ros``, ``tf2_py`` and ``tf2_geometry_msgs`` in
``stubs/`` re-export these modules.
"""
