"""A demo node for the command-line tool tests; runs under Debian's rospy and under minros.

usage: cli_demo_node.py NAME [--rate HZ] [--listen TOPIC]
Publishes /NAME_chatter (std_msgs/String, "hello N"), /pose (geometry_msgs/PoseStamped),
subscribes /cmd (std_msgs/String), serves ~set_bool (std_srvs/SetBool) and ~trigger
(std_srvs/Trigger). Prints "ready" once everything is registered.
"""

import sys

import rospy
from geometry_msgs.msg import PoseStamped
from std_msgs.msg import String
from std_srvs.srv import SetBool, SetBoolResponse, Trigger, TriggerResponse


def main():
    name = sys.argv[1]
    rate = float(sys.argv[sys.argv.index("--rate") + 1]) if "--rate" in sys.argv else 10.0
    rospy.init_node(name)
    chatter = rospy.Publisher(f"/{name}_chatter", String, queue_size=10)
    pose = rospy.Publisher("/pose", PoseStamped, queue_size=10)
    rospy.Subscriber("/cmd", String, lambda m: None)
    if "--listen" in sys.argv:
        rospy.Subscriber(sys.argv[sys.argv.index("--listen") + 1], String, lambda m: None)

    def set_bool(req):
        return SetBoolResponse(success=req.data, message=f"set to {req.data}")

    def trigger(_req):
        return TriggerResponse(success=True, message="triggered")

    rospy.Service("~set_bool", SetBool, set_bool)
    rospy.Service("~trigger", Trigger, trigger)
    print("ready", flush=True)
    r = rospy.Rate(rate)
    n = 0
    while not rospy.is_shutdown():
        n += 1
        chatter.publish(String(data=f"hello {n}"))
        msg = PoseStamped()
        msg.header.stamp = rospy.Time.now()
        msg.header.frame_id = "map"
        msg.pose.position.x = 1.5
        msg.pose.orientation.w = 1.0
        pose.publish(msg)
        try:
            r.sleep()
        except rospy.ROSInterruptException:
            break


if __name__ == "__main__":
    main()
