"""rospy.topics: Publisher, Subscriber, SubscribeListener (minros.client.topics), and the
topic implementations and manager rospy code reaches (minros.rospy_internals.topics)."""

from minros.client.topics import (  # noqa: F401
    DEFAULT_BUFF_SIZE,
    Publisher,
    SubscribeListener,
    Subscriber,
    Topic,
    _PublisherImpl,
    _SubscriberImpl,
)
from minros.rospy_internals.topics import Poller, _TopicImpl, _TopicManager  # noqa: F401
