"""roslib's rosbuild-era message API (roslib.msgs, roslib.srvs, roslib.gentools).

Before genmsg, roslib kept one process-wide table of message specs (``REGISTERED_TYPES``),
filled per package, and computed md5 sums and full texts from it. Generators and tools of
that era, and ROS's own tests, still call it. These modules keep its data model and names;
the line rules (constants, field declarations, name checks) are minros's (:mod:`..spec`,
:mod:`..loader`), and md5 sums come out as genmsg's do.

``roslib.msgs``/``roslib.srvs`` *are* these modules (the stand-ins put them in
``sys.modules``): callers set ``roslib.msgs._initialized`` and read ``REGISTERED_TYPES``
directly, so the state must have one home.
"""
