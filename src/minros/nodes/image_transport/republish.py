"""republish <in_transport> in:=<in_base_topic> [out_transport] out:=<out_base_topic>

Transports: raw (sensor_msgs/Image on the base topic) and compressed (CompressedImage on
<base>/compressed). Without out_transport, both outputs are offered and each is made only
while it has subscribers. Compression parameters as compressed_image_transport names them:
<out>/compressed/format (jpeg|png), jpeg_quality (80), png_level (9)."""

from __future__ import annotations

import sys
from typing import Any, List, Optional

import minros
from minros.image_transport import CompressionError, decode, encode
from sensor_msgs.msg import CompressedImage, Image

TRANSPORTS = ("raw", "compressed")


def main(argv: Optional[List[str]] = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    args = minros.myargv(argv)[1:]
    if args[:1] in (["-h"], ["--help"]):
        print(__doc__)
        return 0
    if not 1 <= len(args) <= 2 or any(a not in TRANSPORTS for a in args):
        print("Usage: republish in_transport in:=<in_base_topic> [out_transport] "
              "out:=<out_base_topic>\n" + f"transports: {', '.join(TRANSPORTS)} (theora and "
              "compressedDepth are not available in minros)", file=sys.stderr)
        return 1
    in_transport = args[0]
    out_transports = [args[1]] if len(args) == 2 else list(TRANSPORTS)
    minros.init_node("image_republisher", argv=argv, anonymous=True)
    in_topic, out_topic = minros.resolve_name("in"), minros.resolve_name("out")
    if in_topic == out_topic and in_transport in out_transports:
        minros.logfatal(f"in and out are both {in_topic}: remap out:=<another topic>")
        return 1
    params = f"{out_topic}/compressed"
    fmt = minros.get_param(f"{params}/format", "jpeg")
    quality = int(minros.get_param(f"{params}/jpeg_quality", 80))
    level = int(minros.get_param(f"{params}/png_level", 9))
    raw_pub = minros.Publisher(out_topic, Image, queue_size=1) \
        if "raw" in out_transports else None
    compressed_pub = minros.Publisher(f"{out_topic}/compressed", CompressedImage, queue_size=1) \
        if "compressed" in out_transports else None
    warned: List[str] = []

    def on_image(msg: Any, raw: Optional[Any] = None) -> None:
        try:
            if raw_pub is not None and (raw_pub.get_num_connections() or len(out_transports) == 1):
                raw_pub.publish(raw if raw is not None else msg)
            if compressed_pub is not None and (compressed_pub.get_num_connections()
                                               or len(out_transports) == 1):
                compressed_pub.publish(msg if raw is None and isinstance(msg, CompressedImage)
                                       else encode(msg, fmt, quality, level))
        except CompressionError as exc:
            if str(exc) not in warned:  # once per kind of problem, not per frame
                warned.append(str(exc))
                minros.logerr(f"republish: {exc}")

    def on_compressed(msg: Any) -> None:
        try:
            raw = decode(msg) if raw_pub is not None else None
        except CompressionError as exc:
            if str(exc) not in warned:
                warned.append(str(exc))
                minros.logerr(f"republish: {exc}")
            return
        if raw is None:
            on_image(msg, None)
        else:
            if compressed_pub is not None and compressed_pub.get_num_connections():
                compressed_pub.publish(msg)
            if raw_pub is not None and (raw_pub.get_num_connections() or len(out_transports) == 1):
                raw_pub.publish(raw)

    if in_transport == "raw":
        minros.Subscriber(in_topic, Image, on_image, queue_size=1, buff_size=1 << 24)
    else:
        minros.Subscriber(f"{in_topic}/compressed", CompressedImage, on_compressed, queue_size=1)
    minros.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
