"""rospy.topics: Publisher, Subscriber, SubscribeListener (minros.topics)."""

from minros.topics import (  # noqa: F401
    Publisher,
    SubscribeListener,
    Subscriber,
    Topic,
)
