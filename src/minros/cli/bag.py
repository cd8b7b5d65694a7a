"""``rosbag`` / ``minros bag``: record, play, info, filter, compress, decompress, reindex, check,
and convert (minros's: ROS 1 bags to ROS 2 recordings and back).

The options, help texts, messages and exit statuses are rosbag's (ros_comm noetic); the work
is done by :mod:`minros.bag`.
"""

from __future__ import annotations

import collections
import optparse
import os
import sys
from typing import Any, Callable, Dict, List, Optional

from minros.tools.common import strip_ros_args

DESCRIPTIONS = {
    "check": "Determine whether a bag is playable in the current system, or if it can be migrated.",
    "compress": "Compress one or more bag files.",
    "convert": "Convert a bag to a ROS 2 recording (rosbag2), or a ROS 2 recording to a bag.",
    "decompress": "Decompress one or more bag files.",
    "decrypt": "Decrypt one or more bag files.",
    "encrypt": "Encrypt one or more bag files.",
    "filter": "Filter the contents of the bag.",
    "fix": "Repair the messages in a bag file so that it can be played in the current system.",
    "info": "Summarize the contents of one or more bag files.",
    "play": "Play back the contents of one or more bag files in a time-synchronized fashion.",
    "record": "Record a bag file with the contents of specified topics.",
    "reindex": "Reindexes one or more bag files.",
}


def _parser(prog: str, usage: str, description: str, **kw) -> optparse.OptionParser:
    """``prog`` is the tool ("rosbag" or "minros bag"): usage errors read "<prog>: error: ..."."""
    return optparse.OptionParser(usage=usage.replace("rosbag", prog, 1), description=description,
                                 prog=prog, **kw)


def _fail(text: str, status: int = 1) -> int:
    sys.stdout.flush()
    print(text, file=sys.stderr)
    return status


# ---------------------------------------------------------------------------------------------
# record

def _handle_split(option: Any, opt_str: Any, value: Any, parser: Any) -> None:
    parser.values.split = True
    if parser.rargs and parser.rargs[0].isdigit():
        print('Use of "--split <MAX_SIZE>" has been deprecated.  Please use --split --size '
              "<MAX_SIZE> or --split --duration <MAX_DURATION>", file=sys.stderr)
        parser.values.size = int(parser.rargs.pop(0))


def record_parser(prog: str, node: bool = False) -> optparse.OptionParser:
    p = _parser(prog, "rosbag record TOPIC1 [TOPIC2 TOPIC3 ...]", DESCRIPTIONS["record"],
                formatter=optparse.IndentedHelpFormatter())
    p.add_option("-a", "--all", dest="all", default=False, action="store_true", help="record all topics")
    p.add_option("-e", "--regex", dest="regex", default=False, action="store_true", help="match topics using regular expressions")
    p.add_option("-p", "--publish", dest="publish", default=False, action="store_true", help="publish a msg when the record begin")
    p.add_option("-x", "--exclude", dest="exclude_regex", default="", action="store", help="exclude topics matching the follow regular expression (subtracts from -a or regex)")
    p.add_option("-q", "--quiet", dest="quiet", default=False, action="store_true", help="suppress console output")
    p.add_option("-o", "--output-prefix", dest="prefix", default=None, action="store", help="prepend PREFIX to beginning of bag name (name will always end with date stamp)")
    p.add_option("-O", "--output-name", dest="name", default=None, action="store", help="record to bag with name NAME.bag")
    p.add_option("--split", dest="split", default=False, callback=_handle_split, action="callback", help="split the bag when maximum size or duration is reached")
    p.add_option("--max-splits", dest="max_splits", type="int", action="store", help="Keep a maximum of N bag files, when reaching the maximum erase the oldest one to keep a constant number of files.", metavar="MAX_SPLITS")
    p.add_option("--size", dest="size", type="int", action="store", help="record a bag of maximum size SIZE MB. (Default: infinite)", metavar="SIZE")
    p.add_option("--duration", dest="duration", type="string", action="store", help="record a bag of maximum duration DURATION in seconds, unless 'm', or 'h' is appended.", metavar="DURATION")
    p.add_option("-b", "--buffsize", dest="buffsize", default=256, type="int", action="store", help="use an internal buffer of SIZE MB (Default: %default, 0 = infinite)", metavar="SIZE")
    p.add_option("--chunksize", dest="chunksize", default=768, type="int", action="store", help="Advanced. Record to chunks of SIZE KB (Default: %default)", metavar="SIZE")
    p.add_option("-l", "--limit", dest="num", default=0, type="int", action="store", help="only record NUM messages on each topic")
    p.add_option("--node", dest="node", default=None, type="string", action="store", help="record all topics subscribed to by a specific node")
    p.add_option("-j", "--bz2", dest="compression", default=None, action="store_const", const="bz2", help="use BZ2 compression")
    p.add_option("--lz4", dest="compression", action="store_const", const="lz4", help="use LZ4 compression")
    p.add_option("--tcpnodelay", dest="tcpnodelay", action="store_true", help="Use the TCP_NODELAY transport hint when subscribing to topics.")
    p.add_option("--udp", dest="udp", action="store_true", help="Use the UDP transport hint when subscribing to topics.")
    p.add_option("--repeat-latched", dest="repeat_latched", action="store_true", help="Repeat latched msgs at the start of each new bag file.")
    if node:  # what the record program itself (rosrun rosbag record) accepts besides
        p.add_option("--topic", dest="extra_topics", default=[], action="append", help="topic to record")
        p.add_option("-L", "--min-space", dest="min_space", default="1G", help="Minimum allowed space on recording device (use G,M,k multipliers)")
    return p


def record_cmd(argv: List[str], prog: str = "rosbag", node: bool = False) -> int:
    p = record_parser(prog, node)
    options, args = p.parse_args(strip_ros_args(argv))
    if node:
        args += options.extra_topics
    if not args and not options.all and not options.node:
        p.error("You must specify a topic name or else use the '-a' option.")
    if options.prefix is not None and options.name is not None:
        p.error("Can't set both prefix and name.")
    if options.split and not options.duration and not options.size:
        p.error("Split specified without giving a maximum duration or size")
    from minros.bag.record import RecordOptions, parse_duration, record

    if options.duration:
        try:
            parse_duration(options.duration)
        except ValueError as exc:
            return _fail(f"Error reading options: {exc}")
    opts = RecordOptions(
        topics=args, record_all=options.all, regex=options.regex,
        exclude=options.exclude_regex or None, quiet=options.quiet, prefix=options.prefix,
        name=options.name, split=options.split, max_splits=options.max_splits or 0,
        size_mb=options.size or 0, duration=options.duration, buffsize_mb=options.buffsize,
        chunksize_kb=options.chunksize, limit=options.num, node=options.node,
        compression=options.compression or "none", tcpnodelay=bool(options.tcpnodelay),
        udp=bool(options.udp), repeat_latched=bool(options.repeat_latched),
        publish=options.publish)
    return _run_node(lambda: record(opts, argv))


def _run_node(fn: Callable[[], int]) -> int:
    from minros.bag.errors import ROSBagException
    from minros.exceptions import ROSException

    try:
        return fn()
    except (ROSBagException, ROSException, OSError) as exc:
        return _fail(f"[FATAL] {exc}")
    except KeyboardInterrupt:
        return 0


# ---------------------------------------------------------------------------------------------
# play

def _collect(attr: str) -> Callable:
    def handle(option: Any, opt_str: Any, value: Any, parser: Any) -> None:
        found = []
        for arg in parser.rargs:
            if arg.startswith("-") and len(arg) > 1:
                break
            found.append(arg)
        getattr(parser.values, attr).extend(found)
        del parser.rargs[:len(found)]

    return handle


def play_parser(prog: str) -> optparse.OptionParser:
    p = _parser(prog, "rosbag play BAGFILE1 [BAGFILE2 BAGFILE3 ...]", DESCRIPTIONS["play"])
    p.add_option("-p", "--prefix", dest="prefix", default="", type="str", help="prefix all output topics")
    p.add_option("-q", "--quiet", dest="quiet", default=False, action="store_true", help="suppress console output")
    p.add_option("-i", "--immediate", dest="immediate", default=False, action="store_true", help="play back all messages without waiting")
    p.add_option("--pause", dest="pause", default=False, action="store_true", help="start in paused mode")
    p.add_option("--queue", dest="queue", default=100, type="int", action="store", help="use an outgoing queue of size SIZE (defaults to %default)", metavar="SIZE")
    p.add_option("--clock", dest="clock", default=False, action="store_true", help="publish the clock time")
    p.add_option("--hz", dest="freq", default=100, type="float", action="store", help="use a frequency of HZ when publishing clock time (default: %default)", metavar="HZ")
    p.add_option("-d", "--delay", dest="delay", default=0.2, type="float", action="store", help="sleep SEC seconds after every advertise call (to allow subscribers to connect)", metavar="SEC")
    p.add_option("-r", "--rate", dest="rate", default=1.0, type="float", action="store", help="multiply the publish rate by FACTOR", metavar="FACTOR")
    p.add_option("-s", "--start", dest="start", default=0.0, type="float", action="store", help="start SEC seconds into the bag files", metavar="SEC")
    p.add_option("-u", "--duration", dest="duration", default=None, type="float", action="store", help="play only SEC seconds from the bag files", metavar="SEC")
    p.add_option("--skip-empty", dest="skip_empty", default=None, type="float", action="store", help="skip regions in the bag with no messages for more than SEC seconds", metavar="SEC")
    p.add_option("-l", "--loop", dest="loop", default=False, action="store_true", help="loop playback")
    p.add_option("-k", "--keep-alive", dest="keep_alive", default=False, action="store_true", help="keep alive past end of bag (useful for publishing latched topics)")
    p.add_option("--try-future-version", dest="try_future", default=False, action="store_true", help="still try to open a bag file, even if the version number is not known to the player")
    p.add_option("--topics", dest="topics", default=[], callback=_collect("topics"), action="callback", help="topics to play back")
    p.add_option("--pause-topics", dest="pause_topics", default=[], callback=_collect("pause_topics"), action="callback", help="topics to pause on during playback")
    p.add_option("--bags", help="bags files to play back from")
    p.add_option("--wait-for-subscribers", dest="wait_for_subscribers", default=False, action="store_true", help="wait for at least one subscriber on each topic before publishing")
    p.add_option("--rate-control-topic", dest="rate_control_topic", default="", type="str", help="watch the given topic, and if the last publish was more than <rate-control-max-delay> ago, wait until the topic publishes again to continue playback")
    p.add_option("--rate-control-max-delay", dest="rate_control_max_delay", default=1.0, type="float", help="maximum time difference from <rate-control-topic> before pausing")
    return p


def play_cmd(argv: List[str], prog: str = "rosbag") -> int:
    p = play_parser(prog)
    options, args = p.parse_args(strip_ros_args(argv))
    if options.bags:
        args.append(options.bags)
    if not args:
        p.error("You must specify at least 1 bag file to play back.")
    if options.rate <= 0:
        return _fail("Error reading options: the rate (-r) must be greater than 0")
    from minros.bag.play import PlayOptions, play

    opts = PlayOptions(
        bags=args, prefix=options.prefix, quiet=options.quiet, immediate=options.immediate,
        pause=options.pause, queue=options.queue, clock=options.clock, hz=options.freq,
        delay=options.delay, rate=options.rate, start=options.start, duration=options.duration,
        skip_empty=options.skip_empty, loop=options.loop, keep_alive=options.keep_alive,
        topics=options.topics, pause_topics=options.pause_topics,
        wait_for_subscribers=options.wait_for_subscribers,
        rate_control_topic=options.rate_control_topic,
        rate_control_max_delay=options.rate_control_max_delay)
    return _run_node(lambda: play(opts, argv))


# ---------------------------------------------------------------------------------------------
# file commands

def info_cmd(argv: List[str], prog: str = "rosbag") -> int:
    p = _parser(prog, "rosbag info [options] BAGFILE1 [BAGFILE2 BAGFILE3 ...]", DESCRIPTIONS["info"])
    p.add_option("-y", "--yaml", dest="yaml", default=False, action="store_true", help="print information in YAML format")
    p.add_option("-k", "--key", dest="key", default=None, action="store", help="print information on the given key")
    p.add_option("--freq", dest="freq", default=False, action="store_true", help="display topic message frequency statistics")
    options, args = p.parse_args(argv)
    if not args:
        p.error("You must specify at least 1 bag file.")
    if options.key and not options.yaml:
        p.error("You can only specify key when printing in YAML format.")
    from minros.bag.ops import info

    return info(args, options.yaml, options.key, options.freq)


def _append(option: Any, opt_str: Any, value: Any, parser: Any) -> None:
    getattr(parser.values, option.dest).append(value)


def convert_parser(prog: str) -> optparse.OptionParser:
    p = _parser(prog, """rosbag convert [options] INBAG OUTBAG

Convert the ROS 1 bag INBAG (.bag, or ROS 1 .mcap) into the ROS 2 recording OUTBAG (a rosbag2
directory: metadata.yaml and an .mcap or .db3 file), or the ROS 2 recording INBAG (a rosbag2
directory, a ROS 2 .mcap or .db3 file) into the ROS 1 bag OUTBAG (.bag, or .mcap). Types map
by ros1_bridge's rules (Header loses seq, time becomes builtin_interfaces/Time, field names
lower case); a type ROS 2 has no counterpart of is made from the bag's own definition. A topic
that cannot be converted is named with the reason, and the rest is converted.""",
                DESCRIPTIONS["convert"])
    p.add_option("--to", dest="to", default=None, choices=["ros2", "ros1"], metavar="ros2|ros1", help="what to convert to (default: ros2 for a ROS 1 bag, ros1 for a ROS 2 recording)")
    p.add_option("--storage", dest="storage", default="mcap", choices=["mcap", "sqlite3"], metavar="mcap|sqlite3", help="the ROS 2 recording's storage (default: %default)")
    p.add_option("--distro", dest="distro", default=None, choices=["jazzy", "kilted", "humble"], metavar="jazzy|kilted|humble", help="the ROS 2 distro whose types and metadata to write (default: jazzy); reading, the one the recording names")
    p.add_option("--topic", dest="topics", default=[], type="string", action="callback", callback=_append, metavar="TOPIC", help="convert only TOPIC: a topic name or a message type, wildcards allowed (repeat for more)")
    p.add_option("--exclude", dest="exclude", default=[], type="string", action="callback", callback=_append, metavar="TOPIC", help="leave out TOPIC: a topic name or a message type, wildcards allowed (repeat for more)")
    p.add_option("-f", "--force", dest="force", default=False, action="store_true", help="replace OUTBAG if it exists")
    p.add_option("-q", "--quiet", dest="quiet", default=False, action="store_true", help="print no plan, progress or summary (warnings still)")
    return p


def convert_cmd(argv: List[str], prog: str = "rosbag") -> int:
    p = convert_parser(prog)
    options, args = p.parse_args(argv)
    if len(args) < 2:
        p.error("You must specify an input bag and an output bag." if not args
                else "You must specify an output bag.")
    if len(args) > 2:
        p.error("Too many arguments.")
    from minros.bag.convert import convert

    return convert(args[0], args[1], options.to, options.storage, options.distro,
                   options.topics, options.exclude, options.quiet, options.force)


def filter_cmd(argv: List[str], prog: str = "rosbag") -> int:
    p = _parser(prog, """rosbag filter [options] INBAG OUTBAG EXPRESSION

EXPRESSION can be any Python-legal expression.

The following variables are available:
 * topic: name of topic
 * m: message
 * t: time of message (t.secs, t.nsecs)""", DESCRIPTIONS["filter"])
    p.add_option("-p", "--print", action="store", dest="verbose_pattern", default=None, metavar="PRINT-EXPRESSION", help="Python expression to print for verbose debugging. Uses same variables as filter-expression")
    options, args = p.parse_args(argv)
    if len(args) == 0:
        p.error("You must specify an in bag, an out bag, and an expression.")
    if len(args) == 1:
        p.error("You must specify an out bag and an expression.")
    if len(args) == 2:
        p.error("You must specify an expression.")
    if len(args) > 3:
        p.error("Too many arguments.")
    from minros.bag.ops import filter_bag

    return filter_bag(args[0], args[1], args[2], options.verbose_pattern)


def _file_op_parser(prog: str, name: str, verb: str) -> optparse.OptionParser:
    p = _parser(prog, f"rosbag {name} [options] BAGFILE1 [BAGFILE2 ...]", f"{verb} one or more bag files.")
    p.add_option("--output-dir", action="store", dest="output_dir", help="write to directory DIR", metavar="DIR")
    p.add_option("-f", "--force", action="store_true", dest="force", help="force overwriting of backup file if it exists")
    p.add_option("-q", "--quiet", action="store_true", dest="quiet", help="suppress noncritical messages")
    return p


def compress_cmd(argv: List[str], prog: str = "rosbag") -> int:
    p = _file_op_parser(prog, "compress", "Compress")
    p.add_option("-j", "--bz2", action="store_const", dest="compression", help="use BZ2 compression", const="bz2", default="bz2")
    p.add_option("--lz4", action="store_const", dest="compression", help="use lz4 compression", const="lz4")
    options, args = p.parse_args(argv)
    if not args:
        p.error("You must specify at least one bag file.")
    from minros.bag import ops

    return ops.compress(args, options.compression, options.output_dir, bool(options.force),
                        bool(options.quiet))


def decompress_cmd(argv: List[str], prog: str = "rosbag") -> int:
    p = _file_op_parser(prog, "decompress", "Decompress")
    options, args = p.parse_args(argv)
    if not args:
        p.error("You must specify at least one bag file.")
    from minros.bag import ops

    return ops.compress(args, "none", options.output_dir, bool(options.force), bool(options.quiet))


def reindex_cmd(argv: List[str], prog: str = "rosbag") -> int:
    p = _file_op_parser(prog, "reindex", "Reindexes")
    p.description = DESCRIPTIONS["reindex"]
    options, args = p.parse_args(argv)
    if not args:
        p.error("You must specify at least one bag file.")
    from minros.bag import ops

    return ops.reindex(args, options.output_dir, bool(options.force), bool(options.quiet))


def print_trans(old: Any, new: Any, indent: int) -> None:
    """One migration as rosbag check prints it: ``* From: type [md5]`` / ``To: ...``."""
    to_text = f"{new._type} [{new._md5sum}]" if new is not None else "Unknown"
    print("    " * indent + f" * From: {old._type} [{old._md5sum}]")
    print("    " * indent + f"   To:   {to_text}")


def _print_migrations(migrations: list) -> None:
    for path, missing in migrations:
        print_trans(path[0].old_class, path[-1].new_class, 0)
        if missing:
            print(f"    {len(missing)} rules missing:")
            for r in missing:
                print_trans(r.old_class, r.new_class, 1)


def _open_checked(path: str) -> Optional[int]:
    """The exit status when ``path`` is not a bag the migrator can read, else None."""
    from minros.bag import Bag, ROSBagException, ROSBagUnindexedException

    try:
        Bag(path).close()
    except ROSBagUnindexedException:
        return _fail(f"ERROR bag unindexed: {path}.  Run rosbag reindex.")
    except (ROSBagException, OSError) as exc:
        return _fail(f"ERROR reading {path}: {exc}")
    return None


def _migrator(rules: List[str], plugins: bool) -> Any:
    from minros.bag.migration import MessageMigrator

    return MessageMigrator(rules, plugins)


def check_cmd(argv: List[str], prog: str = "rosbag") -> int:
    p = _parser(prog, "rosbag check BAG [-g RULEFILE] [EXTRARULES1 EXTRARULES2 ...]", DESCRIPTIONS["check"])
    p.add_option("-g", "--genrules", action="store", dest="rulefile", default=None, help="generate a rulefile named RULEFILE")
    p.add_option("-a", "--append", action="store_true", dest="append", help="append to the end of an existing rulefile after loading it")
    p.add_option("-n", "--noplugins", action="store_true", dest="noplugins", help="do not load rulefiles via plugins")
    options, args = p.parse_args(argv)
    if not args:
        p.error("You must specify a bag file to check.")
    if options.append and options.rulefile is None:
        p.error("Cannot specify -a without also specifying -g.")
    if options.rulefile is not None:
        exists = os.path.isfile(options.rulefile)
        if exists and not options.append:
            p.error(f"The file {options.rulefile} already exists.  Include -a if you intend to append.")
        if not exists and options.append:
            p.error(f"The file {options.rulefile} does not exist, and so -a is invalid.")
    status = _open_checked(args[0])
    if status is not None:
        return status
    from minros.bag import ROSBagException
    from minros.bag.migration import BagMigrationException, checkbag

    try:
        migrator = _migrator(args[1:] + ([options.rulefile] if options.append else []),
                             not options.noplugins)
        migrations = checkbag(migrator, args[0])
    except BagMigrationException as exc:
        return _fail(f"ERROR: {exc}")
    except ROSBagException as exc:
        return _fail(f"ERROR reading {args[0]}: {exc}")
    if not migrations:
        print("Bag file does not need any migrations.")
        return 0
    print("The following migrations need to occur:")
    _print_migrations(migrations)
    missing = [r for _path, rules in migrations for r in rules]
    if options.rulefile is None:
        print("\nAll rules defined.  Bag is ready to be migrated" if not missing
              else "\nTo generate rules, please run with -g <rulefile>")
        return 0
    left = migrator.filter_rules_unique(missing)
    if not left:
        print(f"\nNo additional rule files needed to be generated.  {options.rulefile} not created.")
        return 0
    output = ""
    while left:
        extra = []
        for r in left:
            if r.new_class is not None:
                output += r.get_class_def()
                continue
            # the type moved and no rule says where: ask, as rosbag check does
            new_class = _ask_moved_type(r.old_class._type)
            if new_class is None:
                return _fail("ERROR: no type given for the moved message; no rule file written")
            factory = migrator.make_update_rule(r.old_class, new_class)
            rule = factory(migrator, "GENERATED." + factory.__name__)
            rule.find_sub_paths()
            needed = [x for x in migrator.expand_rules(rule.sub_rules) if not x.valid]
            extra.extend(needed)
            print(f"Creating the migration rule for {new_class._type} requires additional missing rules:")
            for x in needed:
                print_trans(x.old_class, x.new_class, 1)
            output += rule.get_class_def()
        left = migrator.filter_rules_unique(extra)
    with open(options.rulefile, "a") as f:
        f.write(output)
    print(f"\nThe necessary rule files have been written to: {options.rulefile}")
    return 0


def _ask_moved_type(old_type: str) -> Any:
    from minros.msgs import get_message_class

    print(f"The message type {old_type} appears to have moved.  Please enter the type to migrate it to.")
    while True:
        sys.stdout.write(">")
        sys.stdout.flush()
        line = sys.stdin.readline()
        if not line:
            return None
        try:
            return get_message_class(line.strip())
        except Exception:  # noqa: BLE001 - any type that cannot be loaded: ask again
            print(f"'{line.strip()}' could not be found in your system.  Please make sure it is built.")


def fix_cmd(argv: List[str], prog: str = "rosbag") -> int:
    p = _parser(prog, "rosbag fix INBAG OUTBAG [EXTRARULES1 EXTRARULES2 ...]", DESCRIPTIONS["fix"])
    p.add_option("-n", "--noplugins", action="store_true", dest="noplugins", help="do not load rulefiles via plugins")
    p.add_option("--force", action="store_true", dest="force", help="proceed with migrations, even if not all rules defined")
    options, args = p.parse_args(argv)
    if not args:
        p.error("You must pass input and output bag files.")
    if len(args) < 2:
        p.error("You must pass an output bag file.")
    inbag, outbag, rules = args[0], args[1], args[2:]
    ext = os.path.splitext(outbag)[1]
    if ext == ".bmr":
        p.error("Input file should be a bag file, not a rule file.")
    if ext != ".bag":
        p.error("Output file must be a bag file.")
    status = _open_checked(inbag)
    if status is not None:
        return status
    tmp = outbag + ".tmp"
    for path in (outbag, tmp):
        if os.path.exists(path) and not os.access(path, os.W_OK):
            return _fail(f"Don't have permissions to access {path}")
    from minros.bag import ROSBagException
    from minros.bag.migration import BagMigrationException, fixbag2

    try:
        migrations = fixbag2(_migrator(rules, not options.noplugins), inbag, tmp, bool(options.force))
    except (BagMigrationException, ROSBagException, OSError) as exc:
        if os.path.exists(tmp):
            os.remove(tmp)
        return _fail(f"ERROR: {exc}")
    if not migrations:
        os.replace(tmp, outbag)
        print("Bag migrated successfully.")
        return 0
    print("Bag could not be migrated.  The following migrations could not be performed:")
    _print_migrations(migrations)
    print("Try running 'rosbag check' to create the necessary rule files or run 'rosbag fix' "
          "with the '--force' option.")
    if os.path.exists(tmp):
        os.remove(tmp)
    return 1


def _unavailable(name: str, fix: str) -> Callable[[List[str], str], int]:
    """A rosbag command minros does not have: one line, with ``-h`` too (no usage of a command
    that does nothing)."""
    def cmd(argv: List[str], prog: str) -> int:
        return _fail(f"ERROR: rosbag {name} is not available in minros (it reads and writes "
                     f"unencrypted bags only): {fix}")

    return cmd


COMMANDS: Dict[str, Callable[[List[str], str], int]] = {
    "check": check_cmd, "compress": compress_cmd, "convert": convert_cmd,
    "decompress": decompress_cmd,
    "decrypt": _unavailable("decrypt", "decrypt the bag with ROS's rosbag decrypt first"),
    "encrypt": _unavailable("encrypt", "use ROS's rosbag encrypt, or encrypt the whole file "
                                       "(gpg -c BAG)"),
    "filter": filter_cmd,
    "fix": fix_cmd,
    "info": info_cmd, "play": play_cmd, "record": record_cmd, "reindex": reindex_cmd,
}
#: in COMMANDS for scripts written for ROS's rosbag, not offered by --help
UNAVAILABLE = ("decrypt", "encrypt")


def _valid_cmds() -> str:
    out = "Available subcommands:\n"
    for name in sorted([*(c for c in COMMANDS if c not in UNAVAILABLE), "help"]):
        out += f"   {name}  "
        if name in DESCRIPTIONS:
            out += f"\t{DESCRIPTIONS[name]}"
        out += "\n"
    return out


def _help(argv: List[str], prog: str) -> int:
    argv = [a for a in argv if a not in ("-h", "--help")]
    if not argv:
        print(f"Usage: {prog} <subcommand> [options] [args]")
        print()
        print("A bag is a file format in ROS for storing ROS message data. The rosbag command "
              "can record, replay and manipulate bags.")
        print()
        print(_valid_cmds())
        print("For additional information, see http://wiki.ros.org/rosbag")
        print()
        return 0
    if argv[0] in COMMANDS:
        return _run(argv[0], ["-h"], prog)
    print(f"Unknown command: '{argv[0]}'", file=sys.stderr)
    print(_valid_cmds(), file=sys.stderr)
    return 0


def _run(command: str, argv: List[str], prog: str) -> int:
    try:
        return int(COMMANDS[command](argv, prog) or 0)
    except SystemExit as exc:  # optparse: -h (0) and usage errors (2)
        return int(exc.code or 0)


def main(argv: Optional[List[str]] = None, prog: str = "rosbag") -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if "-h" in args or "--help" in args:
        args = ["help"] + [a for a in args if a not in ("-h", "--help")]
    command = args[0] if args else "help"
    if command == "help":
        return _help(args[1:], prog)
    if command not in COMMANDS:
        return _help([command], prog)
    try:
        return _run(command, args[1:], prog)
    except KeyboardInterrupt:
        return 0


def record_node_main() -> int:
    """``rosrun rosbag record ...`` (the record program of the rosbag package)."""
    try:
        return record_cmd(sys.argv[1:], "rosbag", node=True)
    except SystemExit as exc:
        return int(exc.code or 0)


def play_node_main() -> int:
    """``rosrun rosbag play ...`` (the play program of the rosbag package)."""
    try:
        return play_cmd(sys.argv[1:], "rosbag")
    except SystemExit as exc:
        return int(exc.code or 0)


# ---------------------------------------------------------------------------------------------
# rosbag.rosbag_main's Python API (the stand-in re-exports it): the commands above take
# argv without the command name, as rosbag's do, and return the exit status; these are the
# pieces they are built from (bag_op and its ops are minros.bag.ops')

handle_split = _handle_split
handle_topics = _collect("topics")
handle_pause_topics = _collect("pause_topics")
encrypt_cmd = COMMANDS["encrypt"]
decrypt_cmd = COMMANDS["decrypt"]


class RosbagCmds(collections.UserDict):
    """rosbag's command table: name -> function(argv), ``help`` included."""

    def __init__(self) -> None:
        super().__init__()
        self._description: Dict[str, str] = {}
        self["help"] = self.help_cmd

    def add_cmd(self, name: str, function: Callable[[List[str]], Any], description: str) -> None:
        self[name] = function
        self._description[name] = description

    def get_valid_cmds(self) -> str:
        text = "Available subcommands:\n"
        for name in sorted(self.keys()):
            text += f"   {name}  "
            if name in self._description:
                text += f"\t{self._description[name]}"
            text += "\n"
        return text

    def help_cmd(self, argv: List[str]) -> None:
        argv = [a for a in argv if a not in ("-h", "--help")]
        if not argv:
            print("Usage: rosbag <subcommand> [options] [args]")
            print()
            print("A bag is a file format in ROS for storing ROS message data. The rosbag command "
                  "can record, replay and manipulate bags.")
            print()
            print(self.get_valid_cmds())
            print("For additional information, see http://wiki.ros.org/rosbag")
            print()
            return
        if argv[0] in self:
            self[argv[0]](["-h"])
        else:
            print(f"Unknown command: '{argv[0]}'", file=sys.stderr)
            print(self.get_valid_cmds(), file=sys.stderr)


def rosbagmain(argv: Optional[List[str]] = None) -> None:
    """The rosbag command (``argv`` as sys.argv, program name first)."""
    sys.exit(main(list(sys.argv if argv is None else argv)[1:]))


if __name__ == "__main__":  # rosrun rosbag rosbag / <node pkg="rosbag" type="rosbag">
    sys.exit(main(sys.argv[1:]))
