"""rospy_tutorials' nodes, as minros ships them (``rosrun rospy_tutorials talker.py`` ...).

Written for minros after the documented behaviour of ros_tutorials' rospy_tutorials; each module
runs as ``python -m minros.nodes.rospy_tutorials.<node>``.
"""
