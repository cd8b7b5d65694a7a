"""tf2_ros's Buffer: the BufferCore with waiting lookups, ``transform()`` and ``~tf2_frames``.

``lookup_transform(target, source, time, timeout)`` and ``can_transform(..., timeout)`` wait
up to ``timeout`` of ROS time for the transform to become available, as tf2_ros does, but
are woken by each insert instead of polling; they stop waiting early when ROS time jumps
back by more than 3 s (a bag restarting) or the node shuts down.

``transform(msg, target_frame)`` looks up the transform at ``msg.header`` and applies the
converter registered for ``type(msg)`` (tf2_geometry_msgs registers the geometry_msgs
stamped types when imported, as in ROS).
"""

from __future__ import annotations

import copy
import logging
import threading
from typing import Any, Callable, Dict, Tuple

import minros

from .core import BufferCore, to_nsec

#: tf2_ros's polling interval as a fraction of the timeout; here the longest wait between
#: two checks (new data wakes a waiter at once)
DEFAULT_CAN_TRANSFORM_POLLING_SCALE = 0.01
#: a backwards jump of ROS time bigger than this ends a wait (tf2_ros: bag loops)
_JUMP_BACK = 3.0

_frames_service_lock = threading.Lock()
_frames_service: Any = None


def _ros_log(level: int, text: str) -> None:
    """BufferCore's warnings through rospy's logging (console and /rosout)."""
    if level >= logging.ERROR:
        minros.logerr(text)
    else:
        minros.logwarn(text)


def _seconds(value: Any) -> float:
    """A timeout given as rospy.Duration or as seconds."""
    if isinstance(value, (int, float)):
        return float(value)
    return to_nsec(value) / 1e9


class TypeException(Exception):
    """``transform``/``convert`` was given a type nobody registered a converter for."""

    def __init__(self, errstr: str) -> None:
        super().__init__(errstr)
        self.errstr = errstr


class NotImplementedException(Exception):
    """A BufferInterface subclass left lookup_transform/can_transform out."""

    def __init__(self) -> None:
        self.errstr = "CanTransform or LookupTransform not implemented"
        super().__init__(self.errstr)


class TransformRegistration:
    """type -> ``do_transform(msg, transform_stamped)``, shared by every instance."""

    _type_map: Dict[Any, Callable] = {}

    def print_me(self) -> None:
        print(TransformRegistration._type_map)

    def add(self, key: Any, callback: Callable) -> None:
        TransformRegistration._type_map[key] = callback

    def get(self, key: Any) -> Callable:
        try:
            return TransformRegistration._type_map[key]
        except KeyError:
            raise TypeException(f"Type {key} if not loaded or supported") from None


class ConvertRegistration:
    """Conversions between message types and other representations, shared by every instance."""

    _to_msg_map: Dict[Any, Callable] = {}
    _from_msg_map: Dict[Any, Callable] = {}
    _convert_map: Dict[Any, Callable] = {}

    def add_from_msg(self, key: Any, callback: Callable) -> None:
        ConvertRegistration._from_msg_map[key] = callback

    def add_to_msg(self, key: Any, callback: Callable) -> None:
        ConvertRegistration._to_msg_map[key] = callback

    def add_convert(self, key: Any, callback: Callable) -> None:
        ConvertRegistration._convert_map[key] = callback

    @staticmethod
    def _get(table: Dict[Any, Callable], key: Any) -> Callable:
        try:
            return table[key]
        except KeyError:
            raise TypeException(f"Type {key} if not loaded or supported") from None

    def get_from_msg(self, key: Any) -> Callable:
        return self._get(ConvertRegistration._from_msg_map, key)

    def get_to_msg(self, key: Any) -> Callable:
        return self._get(ConvertRegistration._to_msg_map, key)

    def get_convert(self, key: Any) -> Callable:
        return self._get(ConvertRegistration._convert_map, key)


def convert(a: Any, b_type: Any) -> Any:
    """``a`` as type ``b_type``: a direct converter if registered, else through the message."""
    registry = ConvertRegistration()
    try:
        return registry.get_convert((type(a), b_type))(a)
    except TypeException:
        if type(a) is b_type:
            return copy.deepcopy(a)
        return registry.get_from_msg(b_type)(registry.get_to_msg(type(a))(a))


def Stamped(obj: Any, stamp: Any, frame_id: str) -> Any:  # noqa: N802 (tf2_ros's name)
    """Give ``obj`` a std_msgs/Header with ``stamp`` and ``frame_id``."""
    from std_msgs.msg import Header

    obj.header = Header(frame_id=frame_id, stamp=stamp)
    return obj


def _zero() -> Any:
    return minros.Duration(0)


class BufferInterface:
    """tf2_ros's abstract buffer: ``transform``/``transform_full`` on top of lookups."""

    def __init__(self) -> None:
        self.registration = TransformRegistration()

    def transform(self, object_stamped: Any, target_frame: str, timeout: Any = None,
                  new_type: Any = None) -> Any:
        """``object_stamped`` (a stamped message) expressed in ``target_frame``."""
        do_transform = self.registration.get(type(object_stamped))
        header = object_stamped.header
        result = do_transform(object_stamped, self.lookup_transform(
            target_frame, header.frame_id, header.stamp, _zero() if timeout is None else timeout))
        return result if not new_type else convert(result, new_type)

    def transform_full(self, object_stamped: Any, target_frame: str, target_time: Any,
                       fixed_frame: str, timeout: Any = None, new_type: Any = None) -> Any:
        """Like ``transform``, to ``target_frame`` at ``target_time`` through ``fixed_frame``."""
        do_transform = self.registration.get(type(object_stamped))
        header = object_stamped.header
        result = do_transform(object_stamped, self.lookup_transform_full(
            target_frame, target_time, header.frame_id, header.stamp, fixed_frame,
            _zero() if timeout is None else timeout))
        return result if not new_type else convert(result, new_type)

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any,
                         timeout: Any = None) -> Any:
        raise NotImplementedException()

    def lookup_transform_full(self, target_frame: str, target_time: Any, source_frame: str,
                              source_time: Any, fixed_frame: str, timeout: Any = None) -> Any:
        raise NotImplementedException()

    def can_transform(self, target_frame: str, source_frame: str, time: Any,
                      timeout: Any = None) -> bool:
        raise NotImplementedException()

    def can_transform_full(self, target_frame: str, target_time: Any, source_frame: str,
                           source_time: Any, fixed_frame: str, timeout: Any = None) -> bool:
        raise NotImplementedException()


class Buffer(BufferCore, BufferInterface):
    """tf2_ros.Buffer: keeps ``cache_time`` (rospy.Duration, default 10 s) of the tree.

    With ``debug`` (the default) the node offers the ``~tf2_frames`` service
    (tf2_msgs/FrameGraph: the frames as YAML) that ``view_frames`` asks, once per process.
    """

    def __init__(self, cache_time: Any = None, debug: bool = True) -> None:
        BufferCore.__init__(self, cache_time, log=_ros_log)
        BufferInterface.__init__(self)
        self.CAN_TRANSFORM_POLLING_SCALE = DEFAULT_CAN_TRANSFORM_POLLING_SCALE
        self._changed = threading.Condition(threading.Lock())
        self._generation = 0
        self._waiters = 0
        if debug:
            self._advertise_frames()

    def _advertise_frames(self) -> None:
        global _frames_service
        if minros.get_node_uri() is None:  # no node yet: nobody could call it
            return
        with _frames_service_lock:
            if _frames_service is None:
                from tf2_msgs.srv import FrameGraph

                _frames_service = minros.Service("~tf2_frames", FrameGraph, self.__get_frames)
                self.frame_server = _frames_service

    def __get_frames(self, req: Any) -> Any:
        from tf2_msgs.srv import FrameGraphResponse

        return FrameGraphResponse(self.all_frames_as_yaml())

    # Inserts wake the waiters of can_transform; with none waiting this costs one test.

    def set_transform(self, transform: Any, authority: str, is_static: bool = False) -> bool:
        ok = BufferCore.set_transform(self, transform, authority, is_static)
        if self._waiters:
            self._wake()
        return ok

    def set_transform_static(self, transform: Any, authority: str) -> bool:
        ok = BufferCore.set_transform_static(self, transform, authority)
        if self._waiters:
            self._wake()
        return ok

    def set_transforms(self, transforms: Any, authority: str, is_static: bool = False) -> None:
        BufferCore.set_transforms(self, transforms, authority, is_static)
        if self._waiters:
            self._wake()

    def clear(self) -> None:
        BufferCore.clear(self)
        if self._waiters:
            self._wake()

    def _wake(self) -> None:
        with self._changed:
            self._generation += 1
            self._changed.notify_all()

    def _wait_for(self, check: Callable[[], Tuple[bool, str]], timeout: Any) -> Tuple[bool, str]:
        """Call ``check`` until it succeeds or ``timeout`` of ROS time has passed."""
        seconds = _seconds(timeout) if timeout is not None else 0.0
        result = check()
        if result[0] or seconds <= 0.0:
            return result
        start = minros.get_time()
        deadline = start + seconds
        longest = max(seconds * self.CAN_TRANSFORM_POLLING_SCALE, 0.001)
        with self._changed:
            self._waiters += 1
        try:
            while True:
                with self._changed:
                    generation = self._generation
                result = check()
                now = minros.get_time()
                if result[0] or now >= deadline or now + _JUMP_BACK < start:
                    return result
                if minros.is_shutdown():
                    raise minros.ROSInterruptException("ROS shutdown request")
                with self._changed:
                    if generation == self._generation:
                        self._changed.wait(min(longest, deadline - now))
        finally:
            with self._changed:
                self._waiters -= 1

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any,
                         timeout: Any = None) -> Any:
        """The transform from ``source_frame`` to ``target_frame`` at ``time`` (rospy.Time;
        0 for the latest common time), waiting up to ``timeout`` for it."""
        if timeout is not None and _seconds(timeout) > 0.0:
            self.can_transform(target_frame, source_frame, time, timeout)
        return self.lookup_transform_core(target_frame, source_frame, time)

    def lookup_transform_full(self, target_frame: str, target_time: Any, source_frame: str,
                              source_time: Any, fixed_frame: str, timeout: Any = None) -> Any:
        """Source at ``source_time`` to target at ``target_time`` through ``fixed_frame``."""
        if timeout is not None and _seconds(timeout) > 0.0:
            self.can_transform_full(target_frame, target_time, source_frame, source_time,
                                    fixed_frame, timeout)
        return self.lookup_transform_full_core(target_frame, target_time, source_frame,
                                               source_time, fixed_frame)

    def can_transform(self, target_frame: str, source_frame: str, time: Any, timeout: Any = None,
                      return_debug_tuple: bool = False) -> Any:
        """Whether the lookup would succeed (after waiting up to ``timeout``); with
        ``return_debug_tuple``, ``(ok, error text)``."""
        result = self._wait_for(
            lambda: self.can_transform_core(target_frame, source_frame, time), timeout)
        return result if return_debug_tuple else result[0]

    def can_transform_full(self, target_frame: str, target_time: Any, source_frame: str,
                           source_time: Any, fixed_frame: str, timeout: Any = None,
                           return_debug_tuple: bool = False) -> Any:
        """``can_transform`` for the advanced API."""
        result = self._wait_for(lambda: self.can_transform_full_core(
            target_frame, target_time, source_frame, source_time, fixed_frame), timeout)
        return result if return_debug_tuple else result[0]


__all__ = ["Buffer", "BufferInterface", "TransformRegistration",
           "ConvertRegistration", "convert", "Stamped", "TypeException",
           "NotImplementedException", "DEFAULT_CAN_TRANSFORM_POLLING_SCALE"]
