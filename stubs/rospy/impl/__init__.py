"""rospy.impl: rospy's internals have no public API; minros keeps this package so that
``import rospy.impl`` in existing scripts keeps working."""
