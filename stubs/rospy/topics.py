"""rospy.topics: Publisher, Subscriber, SubscribeListener (minros.client.topics)."""

from minros.client.topics import (  # noqa: F401
    Publisher,
    SubscribeListener,
    Subscriber,
    Topic,
)
