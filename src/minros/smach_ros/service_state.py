"""ServiceState: one service call as a smach state (succeeded, aborted, preempted)."""

from __future__ import annotations

import traceback
from typing import Any, Callable, Dict, Optional, Sequence

import minros
from minros import smach
from minros.smach_ros._callbacks import callback_interface

__all__ = ["ServiceState"]


class ServiceState(smach.State):
    """Call ``service_name`` once and succeed with its response.

    The request is ``request`` (or the default request), replaced by ``ud[request_key]``,
    fields from ``request_slots`` keys, then ``request_cb(ud, request)``. The response goes
    to ``response_cb(ud, response)`` (which may return an outcome), ``response_key`` and
    ``response_slots``. A failed call aborts.
    """

    def __init__(self, service_name: str, service_spec: type, request: Any = None,
                 request_cb: Optional[Callable[..., Any]] = None,
                 request_cb_args: Sequence[Any] = (),
                 request_cb_kwargs: Optional[Dict[str, Any]] = None,
                 request_key: Optional[str] = None, request_slots: Sequence[str] = (),
                 response_cb: Optional[Callable[..., Any]] = None,
                 response_cb_args: Sequence[Any] = (),
                 response_cb_kwargs: Optional[Dict[str, Any]] = None,
                 response_key: Optional[str] = None, response_slots: Sequence[str] = (),
                 input_keys: Sequence[str] = (), output_keys: Sequence[str] = (),
                 outcomes: Sequence[str] = ()) -> None:
        super().__init__(outcomes=["succeeded", "aborted", "preempted"])
        self._service_name = service_name
        self._service_spec = service_spec
        self._proxy: Any = None
        self._request = service_spec._request_class() if request is None else request
        self._request_cb = request_cb
        self._request_cb_args = list(request_cb_args)
        self._request_cb_kwargs = dict(request_cb_kwargs or {})
        self._request_cb_keys = callback_interface(self, request_cb, "Request", input_keys,
                                                   output_keys)
        self._request_key = request_key
        if request_key is not None:
            self.register_input_keys([request_key])
        self._request_slots = list(request_slots)
        self.register_input_keys(request_slots)
        self._response_cb = response_cb
        self._response_cb_args = list(response_cb_args)
        self._response_cb_kwargs = dict(response_cb_kwargs or {})
        self._response_cb_keys = callback_interface(self, response_cb, "Response", input_keys,
                                                    output_keys, with_outcomes=True)
        self.register_input_keys(input_keys)
        self.register_output_keys(output_keys)
        self.register_outcomes(outcomes)
        self._response_key = response_key
        if response_key is not None:
            self.register_output_keys([response_key])
        self._response_slots = list(response_slots)
        self.register_output_keys(response_slots)

    def execute(self, ud: Any) -> Optional[str]:
        if self.preempt_requested():
            minros.loginfo(f"Preempting {self._service_name} before sending request.")
            self.service_preempt()
            return "preempted"
        while self._proxy is None:
            if self.preempt_requested():
                minros.loginfo(f"Preempting while waiting for service '{self._service_name}'.")
                self.service_preempt()
                return "preempted"
            if minros.is_shutdown():
                minros.loginfo(f"Shutting down while waiting for service '{self._service_name}'.")
                return "aborted"
            try:
                minros.wait_for_service(self._service_name, 1.0)
                self._proxy = minros.ServiceProxy(self._service_name, self._service_spec)
                minros.logdebug(f"Connected to service '{self._service_name}'")
            except minros.ROSInterruptException:
                minros.logwarn(f"Terminated while waiting for service '{self._service_name}'.")
                return "aborted"
            except minros.ROSException:
                minros.logwarn(f"Still waiting for service '{self._service_name}'...")

        if self._request_key is not None:
            if self._request_key not in ud:
                minros.logerr(f"Requested request key '{self._request_key}' not in userdata "
                              f"struture. Available keys are: {list(ud.keys())}")
                return "aborted"
            self._request = ud[self._request_key]
        for key in self._request_slots:
            if key not in ud:
                minros.logerr(f"Requested request slot key '{key}' is not in userdata strcture. "
                              f"Available keys are: {list(ud.keys())}")
                return "aborted"
            setattr(self._request, key, ud[key])
        if self._request_cb is not None:
            try:
                update = self._request_cb(smach.Remapper(ud, *self._request_cb_keys, {}),
                                          self._request, *self._request_cb_args,
                                          **self._request_cb_kwargs)
            except Exception:  # noqa: BLE001 - user code
                minros.logerr("Could not execute request callback: " + traceback.format_exc())
                return "aborted"
            if update is not None:
                self._request = update
        if self._request is None:
            minros.logerr(f"Attempting to call service {self._service_name} with no request")
            return "aborted"

        try:
            minros.logdebug(f"Calling service {self._service_name} with request:\n{self._request}")
            response = self._proxy(self._request)
        except minros.ServiceException as ex:
            minros.logerr(f"Exception when calling service '{self._service_name}': {ex}")
            return "aborted"
        self._response = response

        outcome = None
        if self._response_cb is not None:
            try:
                outcome = self._response_cb(smach.Remapper(ud, *self._response_cb_keys, {}),
                                            response, *self._response_cb_args,
                                            **self._response_cb_kwargs)
            except Exception:  # noqa: BLE001 - user code
                minros.logerr("Could not execute response callback: " + traceback.format_exc())
                return "aborted"
            if outcome is not None and outcome not in self.get_registered_outcomes():
                minros.logerr(f"Result callback for service {self._service_name}, "
                              f"{self._response_cb} was not registered with the "
                              "response_cb_outcomes argument. The response callback returned "
                              f"'{outcome}' but the only registered outcomes are: "
                              f"{self.get_registered_outcomes()}")
                return "aborted"
        if self._response_key is not None:
            ud[self._response_key] = response
        for key in self._response_slots:
            ud[key] = getattr(response, key)
        return outcome if outcome is not None else "succeeded"
