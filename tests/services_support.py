"""Test helpers for services: rospy_tutorials' services for Debian's rospy, and shared scripts.

minros ships rospy_tutorials' definitions; Debian does not, so the reference side gets genpy
modules generated from the very same .srv files with Debian's ``gensrv_py.py`` (what catkin
would have generated in a workspace).

SERVER and CLIENT are plain rospy scripts: they run unchanged on minros and on Debian's rospy,
so one implementation's answers can be compared with the other's.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

from support import REFERENCE_PYTHON, REPO, reference_env

SHARE_SRV = REPO / "src" / "minros" / "msgs" / "share" / "rospy_tutorials" / "srv"
ADD_TWO_INTS_MD5 = "6a2e34150c00229791cc89ff309fff21"
BAD_TWO_INTS_MD5 = "60962375a49bd6746d7c85dff75ebb9c"


def make_reference_modules(root: Path) -> str:
    """genpy modules of rospy_tutorials' services for Debian's rospy; returns a PYTHONPATH."""
    out = root / "deb" / "rospy_tutorials"
    (out / "srv").mkdir(parents=True, exist_ok=True)
    (out / "__init__.py").write_text("")
    env = reference_env({})
    for name in ("AddTwoInts", "BadTwoInts"):
        subprocess.run([REFERENCE_PYTHON, "/usr/lib/genpy/gensrv_py.py", "-p", "rospy_tutorials",
                        "-o", str(out / "srv"), str(SHARE_SRV / f"{name}.srv")],
                       env=env, check=True, capture_output=True, timeout=60)
    subprocess.run([REFERENCE_PYTHON, "/usr/lib/genpy/gensrv_py.py", "--initpy", "-p",
                    "rospy_tutorials", "-o", str(out / "srv")],
                   env=env, check=True, capture_output=True, timeout=60)
    return str(root / "deb")


#: A service whose handler exercises every return conversion and failure mode (by ``a``).
SERVER = r'''
import sys
import rospy
from rospy_tutorials.srv import AddTwoInts, AddTwoIntsResponse

def handle(req):
    if req.a == 13:
        raise rospy.ServiceException("unlucky number")
    if req.a == 14:
        raise ValueError("boom")
    if req.a == 15:
        return None
    if req.a == 16:
        return {"sum": req.a + req.b}
    if req.a == 17:
        return [req.a + req.b]
    if req.a == 18:
        return req.a + req.b
    if req.a == 19:
        return (1, 2)
    if req.a == 21:  # custom connection headers of the client reach the handler
        return AddTwoIntsResponse(len(req._connection_header.get("cookies", "")))
    print("Returning [%s + %s = %s]" % (req.a, req.b, req.a + req.b), flush=True)
    return AddTwoIntsResponse(req.a + req.b)

def quiet(e, exc_type, exc_value, tb):
    print("error handler saw %s" % e, flush=True)

rospy.init_node(sys.argv[1] if len(sys.argv) > 1 else "adder")
rospy.Service("add_two_ints", AddTwoInts, handle, error_handler=quiet)
print("READY", flush=True)
rospy.spin()
'''

#: Calls a service every way rospy allows and prints one JSON line of results.
CLIENT = r'''
import json
import sys
import rospy
from rospy_tutorials.srv import AddTwoInts, AddTwoIntsRequest, BadTwoInts

name = sys.argv[1]
rospy.wait_for_service(name, timeout=10)
proxy = rospy.ServiceProxy(name, AddTwoInts)
out = {}
for a in range(13, 21):
    try:
        out[str(a)] = proxy(a, 1).sum
    except rospy.ServiceException as e:
        out[str(a)] = "ERR %s" % e
out["call"] = proxy.call(AddTwoIntsRequest(2, 3)).sum
out["cookies"] = rospy.ServiceProxy(name, AddTwoInts, headers={"cookies": "chocolate"})(21, 0).sum
out["kw"] = proxy(a=4, b=5).sum
resp = proxy(1, 1)
out["header"] = sorted(resp._connection_header)
persistent = rospy.ServiceProxy(name, AddTwoInts, persistent=True)
out["persistent"] = [persistent(i, i).sum for i in range(5)]
persistent.close()
try:
    rospy.ServiceProxy(name, BadTwoInts)(1, 2)
except rospy.ServiceException as e:
    out["bad"] = "ERR %s" % e
try:
    rospy.ServiceProxy("/no_such_service", AddTwoInts)(1, 2)
except rospy.ServiceException as e:
    out["missing"] = "ERR %s" % e
try:
    rospy.wait_for_service("/no_such_service", timeout=0.4)
except rospy.ROSException as e:
    out["timeout"] = "%s %s" % (type(e).__name__, e)
try:
    rospy.wait_for_service("/no_such_service", timeout=0)
except ValueError as e:
    out["zero"] = "ValueError %s" % e
print("RESULT " + json.dumps(out, sort_keys=True), flush=True)
'''
