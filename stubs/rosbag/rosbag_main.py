"""rosbag.rosbag_main stand-in: the rosbag command's functions (minros.cli.bag), with the
bag classes and migration pieces rosbag's module hands on."""

from minros.bag import (  # noqa: F401
    Bag,
    Compression,
    ROSBagEncryptException,
    ROSBagEncryptNotSupportedException,
    ROSBagException,
    ROSBagFormatException,
    ROSBagUnindexedException,
)
from minros.bag.migration import MessageMigrator, checkbag, fixbag2  # noqa: F401
from minros.bag.ops import bag_op, change_compression_op, reindex_op  # noqa: F401
from minros.bag.progress import ProgressMeter  # noqa: F401
from minros.cli.bag import (  # noqa: F401
    RosbagCmds,
    check_cmd,
    compress_cmd,
    decompress_cmd,
    decrypt_cmd,
    encrypt_cmd,
    filter_cmd,
    fix_cmd,
    handle_pause_topics,
    handle_split,
    handle_topics,
    info_cmd,
    play_cmd,
    print_trans,
    record_cmd,
    reindex_cmd,
    rosbagmain,
)
