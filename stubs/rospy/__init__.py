"""rospy stand-in: the rospy API served by minros, so unmodified rospy scripts run on minros."""

from __future__ import annotations

from typing import Any

import minros

# rospy imports std_msgs.msg (for Header): scripts that `import rospy, std_msgs` use it
import std_msgs.msg  # noqa: F401
from minros import __all__ as __all__  # noqa: PLC0414 - rospy's public names are minros's
from minros.client.imshow import install as _install_imshow
from minros.msgs import install_import_hook as _install_import_hook

# the submodules scripts reach through the package (rospy.timer.TimerEvent, rospy.exceptions...)
from rospy import (  # noqa: F401
    client,
    core,
    exceptions,
    impl,
    msg,
    msproxy,
    names,
    rostime,
    service,
    timer,
    topics,
)

# A user program starts here: `from my_pkg.msg import Foo` for any package on ROS_PACKAGE_PATH
# without a build step, and cv2.imshow in an OpenCV without GUI publishing its windows for
# `minros web` (client/imshow.py). `import minros` alone installs neither.
_install_import_hook()
_install_imshow()

# Bind every public name now (as rospy's own __init__ does), except the message classes,
# which are imported on first use like in the minros facade.
globals().update({name: getattr(minros, name) for name in __all__
                  if name not in ("Header", "Message")})


def __getattr__(name: str) -> Any:
    return getattr(minros, name)
