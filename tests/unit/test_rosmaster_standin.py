"""The rosmaster package: minros's master under ROS's module layout and names."""

from __future__ import annotations

import subprocess
import sys
import xmlrpc.client

import pytest

import rosmaster
import rosmaster.master
import rosmaster.master_api
from minros.master import MasterHandler
from rosmaster.exceptions import InternalException
from rosmaster.paramserver import ParamDictionary
from rosmaster.registrations import NodeRef, RegistrationManager, Registrations
from support import free_port, wait_for_master


class Pool:
    def __init__(self) -> None:
        self.tasks = []

    def queue_task(self, *args) -> None:
        self.tasks.append(args)


def test_registration_manager_bumps_a_node_registering_from_a_new_uri():
    pool = Pool()
    reg = RegistrationManager(pool)
    reg.register_publisher("/t", "/n", "http://a:1/")
    reg.register_subscriber("/u", "/n", "http://a:1/")
    reg.register_publisher("/t", "/n", "http://b:1/")
    marker, task, args = pool.tasks[0]
    assert marker == "http://a:1/" and args == ("http://a:1/", "/n", "new node registered with same name")
    assert task.__name__ == "shutdown_node_task"
    assert reg.get_node("/n").topic_publications == ["/t"] and not reg.subscribers
    with pytest.raises(InternalException):
        NodeRef("/n", "http://a:1/").add(99, "/x")
    with pytest.raises(InternalException):
        Registrations(Registrations.SERVICE).register("/s", "/n", "http://a:1/")


def test_param_dictionary_notifies_subscribers_but_not_the_setter():
    reg = RegistrationManager(Pool())
    params = ParamDictionary(reg)
    assert params.subscribe_param("/a", ("/n1", "http://n1:1/")) == {}
    params.subscribe_param("/a/b", ("/n2", "http://n2:1/"))
    updates = []
    params.set_param("/a", {"b": 2}, notify_task=updates.extend, caller_id="/n1")
    assert ([], "/a/", {"b": 2}) in updates and ([("/n2", "http://n2:1/")], "/a/b/", 2) in updates
    assert params.search_param("/a/c", "b") == "/a/b"
    updates.clear()
    params.delete_param("/a", notify_task=updates.extend)
    assert ([("/n2", "http://n2:1/")], "/a/b/", {}) in updates and params.get_param_names() == []
    with pytest.raises(KeyError):
        params.get_param("/a")


def test_master_class_serves_and_stops(monkeypatch):
    monkeypatch.setenv("ROS_HOSTNAME", "localhost")
    master = rosmaster.master.Master(0, num_workers=2)
    master.start()
    try:
        assert master.ok() and isinstance(master.handler, MasterHandler)  # minros's own
        proxy = xmlrpc.client.ServerProxy(master.uri)
        assert proxy.setParam("/t", "/p", 3)[0] == 1
        assert proxy.getParam("/t", "/p") == [1, "Parameter [/p]", 3]
        assert proxy.getUri("/t")[2] == master.uri
    finally:
        master.stop()
    assert not master.ok()


@pytest.mark.slow
def test_rosmaster_main_runs_until_the_shutdown_call(tmp_path):
    port = free_port()
    code = "import rosmaster, sys; rosmaster.rosmaster_main(sys.argv)"
    proc = subprocess.Popen([sys.executable, "-c", code, "--core", "-p", str(port)],
                            env={"ROS_HOSTNAME": "localhost", "ROS_LOG_DIR": str(tmp_path),
                                 "PATH": "/usr/bin:/bin"},
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        wait_for_master(port)
        proxy = xmlrpc.client.ServerProxy(f"http://localhost:{port}/")
        assert proxy.shutdown("/test", "done")[0] == 1
        assert proc.wait(10) == 0
    finally:
        proc.kill()
        proc.wait()
    assert rosmaster.DEFAULT_MASTER_PORT == 11311
