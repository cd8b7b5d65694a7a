"""cv_bridge.boost.cv_bridge_boost stand-in: the C++ extension's functions, in Python
(minros.cv_bridge); errors are RuntimeError, as the extension raises them."""

from minros.cv_bridge import (  # noqa: F401
    CV_MAT_CNWrap,
    CV_MAT_DEPTHWrap,
    cvtColor2,
    cvtColorForDisplay,
    getCvType,
)
