"""The rosbag sub-commands that work on files: info, filter, compress, decompress, reindex,
check. Messages and exit statuses are rosbag's; each returns the exit status."""

from __future__ import annotations

import os
import shutil
import sys
from typing import Any, Callable, List, Optional

from minros.bag import bag1
from minros.bag.bag import Bag, is_mcap
from minros.bag.errors import Compression, ROSBagException, ROSBagUnindexedException
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


def _copy_messages(inbag: Bag, outbag: Bag, quiet: bool) -> None:
    meter = None if quiet else ProgressMeter(outbag.filename, inbag._uncompressed_size)
    total = 0
    for topic, raw, t, header in inbag.read_messages(raw=True, return_connection_header=True):
        outbag.write(topic, raw, t, raw=True, connection_header=header)
        if meter is not None:
            total += len(raw[1])
            meter.step(total)
    if meter is not None:
        meter.finish()


def _reindex_into(path: str, quiet: bool) -> None:
    meter = None if quiet else ProgressMeter(path, os.path.getsize(path))
    scan = bag1.reindex_in_place(path, None if meter is None else meter.step)
    if meter is not None:
        meter.finish()
    if scan.skipped:  # damage in the middle (a file that is only cut short is the usual case)
        more = f" and {len(scan.skipped) - 1} more place(s)" if len(scan.skipped) > 1 else ""
        kept = sum(sum(c.counts.values()) for c in scan.chunks)
        _err(f"WARNING {path}: skipped damaged data ({scan.skipped[0]}){more}; kept {kept} messages")


def bag_op(paths: List[str], op: str, compression: str = Compression.NONE,
           output_dir: Optional[str] = None, force: bool = False, quiet: bool = False) -> int:
    """compress / decompress / reindex each bag, keeping the original as ``NAME.orig.EXT``
    when writing in place (rosbag's bag_op)."""
    for path in paths:
        reindex = op == "reindex"
        if reindex and is_mcap(path):
            _err(f"ERROR reading {path}: reindexing MCAP files is not supported by minros")
            continue
        try:
            if reindex:  # the scan reads the whole file: here only what makes it a bag
                bag1.check_version(path)
            else:
                Bag(path, "r").close()
        except (ROSBagException, OSError) as exc:
            _read_error(path, exc)
            continue
        out = path if output_dir is None else os.path.join(output_dir, os.path.basename(path))
        source = path
        if out == path:
            root, ext = os.path.splitext(path)
            backup = f"{root}.orig{ext}"
            if not force and os.path.exists(backup):
                if not quiet:
                    _err(f"Skipping {path}. Backup path {backup} already exists.")
                continue
            try:
                if reindex:
                    shutil.copy(path, backup)
                else:
                    os.rename(path, backup)
            except OSError as exc:
                _err(f"ERROR {'copying' if reindex else 'moving'} {path} to {backup}: {exc}")
                continue
            source = backup
        elif reindex:
            shutil.copy(path, out)
        try:
            if reindex:
                _reindex_into(out, quiet)
                continue
            inbag = Bag(source)
            try:
                outbag = Bag(out, "w", compression=compression)
            except (ROSBagException, OSError) as exc:
                _err(f"ERROR writing to {out}: {exc}")
                inbag.close()
                continue
            try:
                _copy_messages(inbag, outbag, quiet)
            finally:
                outbag.close()
                inbag.close()
        except KeyboardInterrupt:
            if source != path:
                try:
                    if reindex:
                        os.remove(source)
                    else:
                        os.rename(source, path)
                except OSError:
                    pass
            raise
        except (ROSBagException, OSError) as exc:
            _err(f"ERROR operating on {path}: {exc}")
    return 0
