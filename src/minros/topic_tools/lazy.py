"""LazyTransport: a node that subscribes to its inputs only while its outputs have
subscribers (ROS's ``topic_tools.LazyTransport``, for image pipelines and the like)."""

from __future__ import annotations

from typing import Any, List, Optional

import minros

__all__ = ["LazyTransport"]


class LazyTransport(minros.SubscribeListener):
    """Subclasses implement ``subscribe()`` and ``unsubscribe()`` and create their outputs
    with ``self.advertise(...)``; with the ``~lazy`` parameter False they subscribe at once."""

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        # ROS's class calls _post_init after the subclass's __init__ (a metaclass there)
        init = cls.__init__

        def wrapped(self: Any, *args: Any, **kw: Any) -> None:
            init(self, *args, **kw)
            if type(self).__init__ is wrapped:
                self._post_init()

        cls.__init__ = wrapped  # type: ignore[method-assign]

    def __init__(self) -> None:
        super().__init__()
        self._publishers: List[Any] = []
        self._connection_status: Optional[bool] = None
        minros.Timer(minros.Duration(5), self._warn_never_subscribed_cb, oneshot=True)

    def _post_init(self) -> None:
        if not minros.get_param("~lazy", True):
            self.subscribe()
            self._connection_status = True

    def _warn_never_subscribed_cb(self, timer_event: Any) -> None:
        if self._connection_status is None:
            minros.logwarn(f"[{minros.get_name()}] subscribes topics only with child "
                           "subscribers. Set '~lazy' as False to have it always transport "
                           "message.")

    def subscribe(self) -> None:
        raise NotImplementedError("Please overwrite this method")

    def unsubscribe(self) -> None:
        raise NotImplementedError("Please overwrite this method")

    def peer_subscribe(self, *args: Any, **kwargs: Any) -> None:
        if self._connection_status is not True:
            self.subscribe()
            self._connection_status = True

    def peer_unsubscribe(self, *args: Any, **kwargs: Any) -> None:
        if not minros.get_param("~lazy", True) or self._connection_status in (None, False):
            return
        if all(pub.get_num_connections() == 0 for pub in self._publishers):
            self.unsubscribe()
            self._connection_status = False

    def advertise(self, *args: Any, **kwargs: Any) -> Any:
        """``rospy.Publisher(*args, **kwargs)`` with this object as its subscriber listener."""
        if len(args) >= 3 and args[2] is not None or kwargs.get("subscriber_listener"):
            raise ValueError("LazyTransport.advertise sets the subscriber listener itself")
        kwargs["subscriber_listener"] = self
        pub = minros.Publisher(*args, **kwargs)
        self._publishers.append(pub)
        return pub
