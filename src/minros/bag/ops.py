"""The rosbag sub-commands that work on files: info, filter, compress, decompress, reindex,
check. Messages and exit statuses are rosbag's; each returns the exit status."""

from __future__ import annotations

import os
import shutil
import sys
from typing import Any, Callable, List, Optional

from minros.bag import bag1
from minros.bag.bag import Bag, is_mcap
from minros.bag.errors import (
    ROSBagEncryptException,
    ROSBagEncryptNotSupportedException,
    ROSBagException,
    ROSBagUnindexedException,
)
from minros.bag.progress import ProgressMeter


def _err(text: str) -> None:
    sys.stdout.flush()
    print(text, file=sys.stderr)


def _read_error(path: str, exc: Exception) -> None:
    """rosbag's line for a bag it could not read: unindexed ones are told to reindex."""
    if isinstance(exc, ROSBagUnindexedException):
        _err(f"ERROR bag unindexed: {path}.  Run rosbag reindex.")
    else:
        _err(f"ERROR reading {path}: {exc}")


def info(paths: List[str], yaml: bool = False, key: Optional[str] = None,
         freq: bool = False) -> int:
    for i, path in enumerate(paths):
        try:
            bag = Bag(path, "r", skip_index=not freq)
            try:
                if yaml:
                    text = bag._get_yaml_info(key=key)
                    if text is not None:
                        print(text)
                else:
                    print(bag)
            finally:
                bag.close()
            if i < len(paths) - 1:
                print("---")
        except BrokenPipeError:
            raise
        except (ROSBagException, OSError) as exc:
            _read_error(path, exc)
            return 1
    return 0


def compile_expression(expr: str, what: str = "filter expression") -> Callable[..., Any]:
    """``lambda topic, m, t: <expr>``, as rosbag filter evaluates it."""
    try:
        return eval(f"lambda topic, m, t: {expr}")  # noqa: S307 - rosbag filter's documented contract
    except SyntaxError as exc:
        raise ROSBagException(f"invalid {what} '{expr}': {exc.msg}") from None


def filter_bag(inbag_path: str, outbag_path: str, expr: str,
               print_expr: Optional[str] = None) -> int:
    if not os.path.isfile(inbag_path):
        _err(f"Cannot locate input bag file [{inbag_path}]")
        return 2
    if os.path.realpath(inbag_path) == os.path.realpath(outbag_path):
        _err(f"Cannot use same file as input and output [{inbag_path}]")
        return 3
    try:
        keep = compile_expression(expr)
        show = compile_expression(print_expr, "print expression") if print_expr else None
        inbag = Bag(inbag_path)
    except ROSBagUnindexedException as exc:
        _read_error(inbag_path, exc)
        return 1
    except ROSBagException as exc:
        _err(f"ERROR: {exc}")
        return 1
    outbag = Bag(outbag_path, "w")
    try:
        meter = ProgressMeter(outbag_path, inbag._uncompressed_size)
        total = 0
        for topic, raw, t, header in inbag.read_messages(raw=True, return_connection_header=True):
            _type, data, _md5, _pos, pytype = raw
            msg = pytype()
            msg.deserialize(data)
            try:
                matched = keep(topic, msg, t)
            except Exception as exc:
                raise ROSBagException(f"the filter expression failed on a message of {topic}: "
                                      f"{type(exc).__name__}: {exc}") from None
            if matched:
                outbag.write(topic, raw, t, raw=True, connection_header=header)
            if show is not None:
                print("MATCH" if matched else "NO MATCH", show(topic, msg, t))
            total += len(data)
            meter.step(total)
        meter.finish()
    except ROSBagException as exc:
        _err(f"\nERROR: {exc}")
        return 1
    finally:
        inbag.close()
        outbag.close()
    return 0


# -- the in-place operations (compress, decompress, reindex): one walk over the bags

def _each_bag(paths: List[str], prepare: Callable[[str], bool],
              run: Callable[[str, str, bool], None], output_dir: Optional[str],
              force: bool, quiet: bool) -> None:
    """For each bag: ``prepare(path)`` checks that it can be read and says whether to start
    from a copy of it (a ROSBagException or OSError is reported and the bag skipped); the
    output is the bag itself (the input kept as ``NAME.orig.EXT``, moved or copied) or its
    name in ``output_dir``; then ``run(source, out, copy)``. Ctrl-C puts the original back."""
    for path in paths:
        try:
            copy = prepare(path)
        except (ROSBagException, OSError) as exc:
            _read_error(path, exc)
            continue
        out = path if output_dir is None else os.path.join(output_dir, os.path.basename(path))
        backup = None
        source = path
        if out == path:
            root, ext = os.path.splitext(path)
            backup = f"{root}.orig{ext}"
            if not force and os.path.exists(backup):
                if not quiet:
                    _err(f"Skipping {path}. Backup path {backup} already exists.")
                continue
            try:
                (shutil.copy if copy else os.rename)(path, backup)
            except OSError as exc:
                _err(f"ERROR {'copying' if copy else 'moving'} {path} to {backup}: {exc}")
                continue
            source = backup
        elif copy:
            shutil.copy(path, out)
            source = out
        try:
            run(source, out, copy)
        except KeyboardInterrupt:
            if backup is not None:
                try:
                    if copy:
                        os.remove(backup)
                    else:
                        os.rename(backup, path)
                except OSError:
                    pass
            raise
        except (ROSBagException, OSError) as exc:
            _err(f"ERROR operating on {path}: {exc}")


def bag_op(inbag_filenames: List[str], allow_unindexed: bool, open_inbag: bool,
           copy_fn: Callable[[Any], bool], op: Callable[..., None],
           output_dir: Optional[str] = None, force: bool = False, quiet: bool = False) -> None:
    """rosbag_main's bag_op: run ``op(inbag, outbag, quiet=quiet)`` on each bag, writing in
    place (the input kept as ``NAME.orig.EXT``) or into ``output_dir``. ``copy_fn(bag)`` says
    whether to start from a copy of the input (opened for appending) rather than an empty
    bag; without ``open_inbag``, ``op`` gets the input's file name."""
    def prepare(path: str) -> bool:
        if not open_inbag:
            return False
        with Bag(path, "r", allow_unindexed=allow_unindexed) as inbag:
            return bool(copy_fn(inbag))

    def run(source: str, out: str, copy: bool) -> None:
        inbag: Any = Bag(source, "r", allow_unindexed=allow_unindexed) if open_inbag else source
        try:
            try:
                outbag = Bag(out, "a" if copy else "w", allow_unindexed=allow_unindexed)
            except (ROSBagException, OSError) as exc:
                _err(f"ERROR writing to {out}: {exc}")
                return
            try:
                op(inbag, outbag, quiet=quiet)
            except ROSBagException as exc:
                _err(f"\nERROR operating on {source}: {exc}")
            finally:
                outbag.close()
        finally:
            if open_inbag:
                inbag.close()

    _each_bag(inbag_filenames, prepare, run, output_dir, force, quiet)


def change_compression_op(inbag: Bag, outbag: Bag, compression: str, quiet: bool) -> None:
    """Copy every message of ``inbag`` into ``outbag`` with ``compression`` (as recorded:
    raw bytes, connection headers kept), with rosbag's progress bar unless ``quiet``."""
    outbag.compression = compression
    meter = None if quiet else ProgressMeter(outbag.filename, inbag._uncompressed_size)
    total = 0
    for topic, msg, t, header in inbag.read_messages(raw=True, return_connection_header=True):
        outbag.write(topic, msg, t, raw=True, connection_header=header)
        if meter is not None:
            total += len(msg[1])
            meter.step(total)
    if meter is not None:
        meter.finish()


def reindex_op(inbag: Bag, outbag: Bag, quiet: bool) -> None:
    """rosbag_main's reindex_op: rebuild ``outbag``'s index (a copy of ``inbag`` opened for
    appending) from its chunks; damage past the last good chunk ends the scan, as in rosbag."""
    meter = None if quiet else ProgressMeter(outbag.filename, outbag.size)
    try:
        for offset in outbag.reindex():
            if meter is not None:
                meter.step(offset)
    except (ROSBagEncryptNotSupportedException, ROSBagEncryptException):
        raise
    except Exception:  # noqa: BLE001 - damage past the last good chunk ends the scan, as in rosbag
        pass
    if meter is not None:
        meter.finish()


def compress(paths: List[str], compression: str, output_dir: Optional[str] = None,
             force: bool = False, quiet: bool = False) -> int:
    """``rosbag compress`` (``compression`` bz2 or lz4) and ``decompress`` (``none``)."""
    def op(inbag: Bag, outbag: Bag, quiet: bool) -> None:
        change_compression_op(inbag, outbag, compression, quiet)

    bag_op(paths, False, True, lambda bag: False, op, output_dir, force, quiet)
    return 0


def reindex(paths: List[str], output_dir: Optional[str] = None, force: bool = False,
            quiet: bool = False) -> int:
    """``rosbag reindex``: the index rebuilt in a copy of each bag. Unlike rosbag's, the scan
    goes past damage in the middle (to the next chunk it can read) and says what it skipped;
    only the first line is read before copying (rosbag opens the whole bag to look at it)."""
    def prepare(path: str) -> bool:
        if is_mcap(path):
            raise ROSBagException("reindexing MCAP files is not supported by minros")
        bag1.check_version(path)
        return True

    def run(_source: str, out: str, _copy: bool) -> None:
        meter = None if quiet else ProgressMeter(out, os.path.getsize(out))
        scan = bag1.reindex_in_place(out, None if meter is None else meter.step)
        if meter is not None:
            meter.finish()
        if scan.skipped:  # damage in the middle (a file only cut short is the usual case)
            more = f" and {len(scan.skipped) - 1} more place(s)" if len(scan.skipped) > 1 else ""
            kept = sum(sum(c.counts.values()) for c in scan.chunks)
            _err(f"WARNING {out}: skipped damaged data ({scan.skipped[0]}){more}; kept {kept} messages")

    _each_bag(paths, prepare, run, output_dir, force, quiet)
    return 0
