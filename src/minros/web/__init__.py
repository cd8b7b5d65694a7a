"""``minros web``: rosbridge v2 (with rosapi), the Foxglove WebSocket protocol and
web_video_server's endpoints on one port, plus the headless ``cv2.imshow`` bridge.

Modules: ``convert`` and ``cbor`` (rosbridge's message encodings), ``foxglove_protocol`` (frame
codecs), ``rosapi`` (introspection services), ``outbox`` (bounded per-client queues),
``rosbridge`` and ``foxglove`` (one client session each), ``video`` (image feeds, JPEG),
``state`` (the ROS side, one object), ``server`` (the websockets server), ``node`` (running it).
Importing this package imports none of them. The nodes' side of the imshow bridge (windows
published as image topics) is ``minros.client.imshow``, installed by ``import rospy``.
"""
