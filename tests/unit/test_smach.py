"""smach (minros.smach through the `smach` stand-in): state machines, userdata and
remapping, the containers, preemption, and the errors ROS's smach raises."""

from __future__ import annotations

import threading

import pytest

import smach


@pytest.fixture(autouse=True)
def quiet_loggers():
    lines = []
    smach.set_loggers(lambda m: lines.append(("info", m)), lambda m: lines.append(("warn", m)),
                      lambda m: None, lambda m: lines.append(("error", m)))
    yield lines
    smach.set_loggers(print, print, print, print)


class Counter(smach.State):
    def __init__(self, limit: int) -> None:
        super().__init__(outcomes=["again", "done"], io_keys=["n"])
        self.limit = limit

    def execute(self, ud):
        ud.n += 1
        return "again" if ud.n < self.limit else "done"


class Waiter(smach.State):
    """Blocks until preempted (or released), then services the preempt."""

    def __init__(self) -> None:
        super().__init__(outcomes=["released", "preempted"])
        self.started = threading.Event()
        self.release = threading.Event()

    def execute(self, ud):
        self.started.set()
        while not self.release.wait(0.01):
            if self.preempt_requested():
                self.service_preempt()
                return "preempted"
        return "released"


def outcome(name: str, **keys):
    return smach.CBState(lambda ud: name, outcomes=[name], **keys)


def test_transitions_remapping_and_output_keys() -> None:
    sm = smach.StateMachine(outcomes=["finished"], input_keys=["start"], output_keys=["total"])
    with sm:
        smach.StateMachine.add("COUNT", Counter(4), transitions={"again": "COUNT",
                                                                 "done": "finished"},
                               remapping={"n": "total"})
    sm.userdata.total = 1
    parent = smach.UserData()
    parent.start = 0
    assert sm.execute(smach.Remapper(parent, ["start"], ["total"])) == "finished"
    assert parent.total == 4
    assert sm.get_internal_edges() == [("again", "COUNT", "COUNT"), ("done", "COUNT", "finished")]


def test_unbound_outcome_ends_the_machine_under_its_own_name() -> None:
    sm = smach.StateMachine(outcomes=["x"])
    with sm:
        smach.StateMachine.add("A", outcome("x"))
    assert sm.execute() == "x"


def test_input_only_keys_are_read_only_and_undeclared_keys_are_refused(quiet_loggers) -> None:
    class Box:
        value = 1

    seen = {}

    def body(ud):
        seen["value"] = ud.box.value
        with pytest.raises(TypeError):
            ud.box.value = 2  # input-only: a read-only view
        ud.out = 7
        ud.not_declared = 8  # refused with an error log, not written
        with pytest.raises(smach.InvalidUserCodeError):
            _ = ud.secret
        return "ok"

    sm = smach.StateMachine(outcomes=["ok"])
    sm.userdata.box = Box()
    sm.userdata.secret = 1
    with sm:
        smach.StateMachine.add("S", smach.CBState(body, outcomes=["ok"], input_keys=["box"],
                                                  output_keys=["out", "nothing"]))
    assert sm.execute() == "ok"
    assert seen == {"value": 1}
    assert sm.userdata.out == 7
    assert "not_declared" not in sm.userdata
    assert any("not_declared" in m for level, m in quiet_loggers if level == "error")


def test_missing_userdata_key_is_a_key_error_and_hasattr_works() -> None:
    ud = smach.UserData()
    with pytest.raises(KeyError):
        ud["nope"]
    assert not hasattr(ud, "nope")
    ud.yes = 1
    assert ud.yes == 1 and ud.keys() == ["yes"]


def test_constants_are_written_when_the_state_is_entered() -> None:
    got = []
    sm = smach.StateMachine(outcomes=["ok"])
    with sm:
        smach.StateMachine.add("S", smach.CBState(lambda ud: got.append(ud.speed) or "ok",
                                                  outcomes=["ok"], input_keys=["speed"]),
                               constants={"speed": 0.5})
    assert sm.execute() == "ok" and got == [0.5]


def test_construction_errors() -> None:
    with pytest.raises(smach.InvalidStateError):
        smach.StateMachine.add("A", outcome("x"))  # no container open
    sm = smach.StateMachine(outcomes=["x"])
    with pytest.raises(smach.InvalidTransitionError):
        with sm:
            smach.StateMachine.add("A", outcome("x"), transitions={"y": "B"})
    sm2 = smach.StateMachine(outcomes=["x"])
    with sm2:
        smach.StateMachine.add("A", outcome("x"), transitions={"x": "NOWHERE"})
    with pytest.raises(smach.InvalidTransitionError, match="unknown states: \\['NOWHERE'\\]"):
        sm2.check_consistency()
    assert sm2.execute() is None  # an inconsistent machine does not run
    assert not smach.Container._any_containers_opened()


def test_outcome_not_registered_raises() -> None:
    sm = smach.StateMachine(outcomes=["x"])
    with sm:
        smach.StateMachine.add("A", smach.CBState(lambda ud: "y", outcomes=["x"]))
    with pytest.raises(smach.InvalidTransitionError, match="only has registered outcomes"):
        sm.execute()


def test_user_exception_becomes_invalid_user_code_error() -> None:
    def boom(ud):
        raise ValueError("bad")

    sm = smach.StateMachine(outcomes=["x"])
    with sm:
        smach.StateMachine.add("A", smach.CBState(boom, outcomes=["x"]))
    with pytest.raises(smach.InvalidUserCodeError, match="ValueError: bad"):
        sm.execute()
    assert not sm.is_running()


def test_sequence_and_add_auto_connect_states_in_order() -> None:
    order = []

    def step(name):
        return smach.CBState(lambda ud: order.append(name) or "next", outcomes=["next", "fail"])

    seq = smach.Sequence(outcomes=["next", "fail"], connector_outcome="next")
    with seq:
        smach.Sequence.add("A", step("A"))
        smach.Sequence.add("B", step("B"))
        smach.Sequence.add("C", step("C"))
    assert seq.execute() == "next" and order == ["A", "B", "C"]

    order.clear()
    sm = smach.StateMachine(outcomes=["next", "fail"])
    with sm:
        smach.StateMachine.add_auto("A", step("A"), ["next"])
        smach.StateMachine.add("B", step("B"))
    assert sm.execute() == "next" and order == ["A", "B"]


def test_nested_machine_and_callbacks() -> None:
    events = []
    inner = smach.StateMachine(outcomes=["inner_done"])
    with inner:
        smach.StateMachine.add("I1", outcome("go"), transitions={"go": "I2"})
        smach.StateMachine.add("I2", outcome("inner_done"))
    outer = smach.StateMachine(outcomes=["end"])
    with outer:
        smach.StateMachine.add("INNER", inner, transitions={"inner_done": "LAST"})
        smach.StateMachine.add("LAST", outcome("end"))
    outer.register_start_cb(lambda ud, states: events.append(("start", states)))
    outer.register_transition_cb(lambda ud, states: events.append(("transition", states)))
    outer.register_termination_cb(lambda ud, states, o: events.append(("end", states, o)))
    assert outer.execute() == "end"
    assert events == [("start", ["INNER"]), ("transition", ["LAST"]), ("end", ["LAST"], "end")]
    assert outer["INNER"] is inner and set(outer.get_children()) == {"INNER", "LAST"}


def test_preempting_a_running_machine_preempts_its_state() -> None:
    waiter = Waiter()
    sm = smach.StateMachine(outcomes=["released", "preempted"])
    with sm:
        smach.StateMachine.add("WAIT", waiter)
    result = []
    runner = threading.Thread(target=lambda: result.append(sm.execute()))
    runner.start()
    assert waiter.started.wait(5)
    sm.request_preempt()
    runner.join(5)
    assert result == ["preempted"]
    assert not sm.preempt_requested()  # serviced by the state, so by the machine


def test_concurrence_outcome_map_prefers_the_most_specific_entry() -> None:
    cc = smach.Concurrence(outcomes=["both", "one", "neither"], default_outcome="neither",
                           outcome_map={"one": {"A": "ok"}, "both": {"A": "ok", "B": "ok"}})
    with cc:
        smach.Concurrence.add("A", outcome("ok"))
        smach.Concurrence.add("B", outcome("ok"))
    assert cc.execute() == "both"
    assert sorted(cc.get_internal_edges()) == [("ok", "A", "both"), ("ok", "A", "one"),
                                               ("ok", "B", "both")]


def test_concurrence_outcome_cb_and_userdata() -> None:
    def writer(ud):
        ud.res = 42  # the state's own name for the container's key 'result'
        return "ok"

    cc = smach.Concurrence(outcomes=["good", "bad"], default_outcome="bad", output_keys=["result"],
                           outcome_cb=lambda outcomes: "good" if outcomes == {"W": "ok"} else None)
    with cc:
        smach.Concurrence.add("W", smach.CBState(writer, outcomes=["ok"], output_keys=["res"]),
                              remapping={"res": "result"})
    parent = smach.UserData()
    assert cc.execute(smach.Remapper(parent, [], ["result"])) == "good"
    assert parent.result == 42


def test_concurrence_child_termination_cb_preempts_the_others() -> None:
    waiter = Waiter()
    cc = smach.Concurrence(outcomes=["done", "other"], default_outcome="other",
                           child_termination_cb=lambda outcomes: True,
                           outcome_map={"done": {"QUICK": "ok", "WAIT": "preempted"}})
    with cc:
        smach.Concurrence.add("QUICK", outcome("ok"))
        smach.Concurrence.add("WAIT", waiter)
    assert cc.execute() == "done"
    assert not waiter.preempt_requested()


def test_concurrence_preempted_from_outside_returns_preempted() -> None:
    waiters = [Waiter(), Waiter()]
    cc = smach.Concurrence(outcomes=["done"], default_outcome="done")
    with cc:
        smach.Concurrence.add("W1", waiters[0])
        smach.Concurrence.add("W2", waiters[1])
    result = []
    runner = threading.Thread(target=lambda: result.append(cc.execute()))
    runner.start()
    assert all(w.started.wait(5) for w in waiters)
    cc.request_preempt()
    runner.join(5)
    assert result == ["preempted"] and not cc.preempt_requested()


def test_concurrence_child_exception_is_raised_by_execute() -> None:
    def boom(ud):
        raise RuntimeError("child failed")

    cc = smach.Concurrence(outcomes=["done"], default_outcome="done")
    with cc:
        smach.Concurrence.add("BAD", smach.CBState(boom, outcomes=["x"]))
    with pytest.raises(smach.InvalidStateError, match="child failed"):
        cc.execute()


def test_concurrence_policy_errors() -> None:
    with pytest.raises(smach.InvalidStateError, match="Default outcome 'x' is unregistered"):
        smach.Concurrence(outcomes=["a"], default_outcome="x")
    empty = smach.Concurrence(outcomes=["a"], default_outcome="a")
    with pytest.raises(smach.InvalidStateError, match="No states"):
        empty.execute()


def test_iterator_loops_breaks_and_maps_the_final_outcome() -> None:
    seen = []

    def body(ud):
        seen.append(ud.it_data)
        return "stop" if ud.it_data == 3 else "continue"

    it = smach.Iterator(outcomes=["found", "none"], input_keys=[], output_keys=[],
                        it=lambda: range(1, 10), exhausted_outcome="none")
    with it:
        smach.Iterator.set_contained_state("BODY", smach.CBState(body, outcomes=["continue",
                                                                                 "stop"]),
                                           loop_outcomes=["continue"],
                                           final_outcome_map={"stop": "found"})
    assert it.execute() == "found" and seen == [1, 2, 3]
    seen.clear()
    it._items = [5, 6]
    assert it.execute() == "none" and seen == [5, 6]
    assert ("continue", "BODY", "BODY") in it.get_internal_edges()


def test_cb_interface_adds_outcomes_and_keys() -> None:
    @smach.cb_interface(outcomes=["special"], input_keys=["a"], output_keys=["b"])
    def cb(ud):
        ud.b = ud.a * 2
        return "special"

    state = smach.CBState(cb)
    assert set(state.get_registered_outcomes()) == {"special"}
    assert state.get_registered_input_keys() == ("a",)
    sm = smach.StateMachine(outcomes=["special"])
    sm.userdata.a = 21
    with sm:
        smach.StateMachine.add("CB", state)
    assert sm.execute() == "special" and sm.userdata.b == 42


def test_shutdown_check_stops_a_looping_machine() -> None:
    calls = []
    smach.set_shutdown_check(lambda: len(calls) > 3)
    try:
        sm = smach.StateMachine(outcomes=["never"])
        with sm:
            smach.StateMachine.add("LOOP", smach.CBState(lambda ud: calls.append(1) or "again",
                                                         outcomes=["again"]),
                                   transitions={"again": "LOOP"})
        assert sm.execute() is None and len(calls) == 4
    finally:
        smach.set_shutdown_check(lambda: False)


def test_submodules_under_ros_names() -> None:
    from smach.state_machine import StateMachine
    from smach.user_data import Remapper, UserData
    from smach.util import cb_interface

    assert StateMachine is smach.StateMachine and UserData is smach.UserData
    assert Remapper is smach.Remapper and cb_interface is smach.cb_interface
    assert smach.container.Container is smach.Container
