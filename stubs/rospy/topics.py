"""rospy.topics: Publisher, Subscriber, SubscribeListener (minros.client.topics); rospy's topic
implementations, which are minros's publication and subscription of a topic
(minros.client.publication, minros.client.subscription); and the topic manager and poller
rospy code reaches (minros.rospy_internals.topics)."""

from minros.client.publication import Publication as _PublisherImpl  # noqa: F401
from minros.client.subscription import Subscription as _SubscriberImpl  # noqa: F401
from minros.client.topics import (  # noqa: F401
    Publisher,
    SubscribeListener,
    Subscriber,
    Topic,
)
from minros.rospy_internals.topics import Poller, _TopicImpl, _TopicManager  # noqa: F401
from minros.wire.tcpros import DEFAULT_BUFF_SIZE  # noqa: F401
