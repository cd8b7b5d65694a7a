"""rospy.topics: Publisher, Subscriber, SubscribeListener (minros.client.topics); rospy's topic
implementations, which are minros's publication and subscription of a topic
(minros.client.publication, minros.client.subscription); and the topic manager and poller
rospy code reaches (minros.rospy_internals.topics). Like rospy's module, its namespace also
has rospy.core's names (``from rospy.core import *``) and the helpers it imports."""

from minros.client.publication import Publication as _PublisherImpl  # noqa: F401
from minros.client.subscription import Subscription as _SubscriberImpl  # noqa: F401
from minros.client.topics import (  # noqa: F401
    Publisher,
    SubscribeListener,
    Subscriber,
    Topic,
)
from minros.exceptions import ROSSerializationException, TransportTerminated  # noqa: F401
from minros.msgs.message import Message  # noqa: F401
from minros.rospy_internals import core as _core
from minros.rospy_internals.msg import args_kwds_to_message, serialize_message  # noqa: F401
from minros.rospy_internals.registration import (  # noqa: F401
    Registration,
    get_registration_listeners,
    get_topic_manager,
    set_topic_manager,
)
from minros.rospy_internals.statistics import SubscriberStatisticsLogger  # noqa: F401
from minros.rospy_internals.tcpros import get_tcpros_handler  # noqa: F401
from minros.rospy_internals.tcpros_pubsub import QueuedConnection  # noqa: F401
from minros.rospy_internals.topics import Poller, _TopicImpl, _TopicManager  # noqa: F401
from minros.wire.tcpros import DEFAULT_BUFF_SIZE  # noqa: F401

python3 = True  # rospy's flag of a Python 3 interpreter
_core.star_import(globals())
