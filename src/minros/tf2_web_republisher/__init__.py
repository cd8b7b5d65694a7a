"""tf2_web_republisher: the transforms a web page asks for, relative to one frame, sent only
when they moved more than a threshold — the server roslibjs's TFClient (the
``tf2_web_republisher`` action: feedback carries the transforms) and roslibpy's TFClient (the
``republish_tfs`` service: a latched ``~tf_repub_N`` TFArray topic, dropped after
``timeout`` without subscribers) talk to. ``pairs`` holds the threshold logic (pure);
``republisher`` the node's side; the program is ``rosrun tf2_web_republisher
tf2_web_republisher``."""

from minros.tf2_web_republisher.pairs import TFPair
from minros.tf2_web_republisher.republisher import TFRepublisher

__all__ = ["TFPair", "TFRepublisher"]
