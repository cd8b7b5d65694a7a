"""The damaged-bag corpus (tests/unit/test_bag_damage.py) against Debian's rosbag: for every
file, minros's ``rosbag reindex`` keeps at least the messages Debian's keeps, minros's
``info``/``check``/``reindex`` print at most one line, and reading raises only the
ROSBagException family. Debian's side runs in one process over the whole corpus (its own
rosbag_main functions, as its command line calls them).
"""

from __future__ import annotations

import collections
import json
import subprocess
from pathlib import Path
from typing import Dict, List

import pytest

from support import REFERENCE_PYTHON, reference_env, require_reference
from unit.test_bag_damage import ROS_FAMILY, damaged_corpus, one_line, read_all, recovered, run_cli

pytestmark = pytest.mark.interop

DEBIAN = r'''
import contextlib, io, json, os, sys
import rosbag
from rosbag import rosbag_main

def classify(fn):
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            fn()
    except SystemExit:
        pass
    except Exception as exc:
        return "traceback " + type(exc).__name__
    text = err.getvalue().strip()
    return "one line" if text and len(text.splitlines()) == 1 else ("ok" if not text else "lines")

def count(path):
    n = 0
    try:
        with rosbag.Bag(path) as b:
            for _ in b.read_messages(raw=True):
                n += 1
    except Exception as exc:
        return n, type(exc).__name__
    return n, None

def read_error(path):
    try:
        with rosbag.Bag(path) as b:
            for _ in b.read_messages():
                pass
    except Exception as exc:
        return type(exc).__name__
    return None

out = {}
outroot = sys.argv[1]
for path in sys.argv[2:]:
    name = os.path.basename(path)
    outdir = os.path.join(outroot, name)
    os.mkdir(outdir)
    info = classify(lambda: rosbag_main.info_cmd([path]))
    reindex = classify(lambda: rosbag_main.reindex_cmd(["-q", "--output-dir", outdir, path]))
    result = os.path.join(outdir, name)
    n, error = count(result) if os.path.exists(result) else (0, "no output")
    out[name] = {"info": info, "reindex": reindex, "recovered": n, "reread": error,
                 "read": read_error(path)}
print(json.dumps(out))
'''


COUNT = r'''
import json, sys
import rosbag
out = {}
for path in sys.argv[1:]:
    n = 0
    try:
        with rosbag.Bag(path) as b:
            for _ in b.read_messages(raw=True):
                n += 1
    except Exception as exc:
        n = "%s: %s" % (type(exc).__name__, exc)
    out[path] = n
print(json.dumps(out))
'''


def debian_counts(files: List[Path]) -> Dict[str, object]:
    """Messages Debian's rosbag.Bag reads from each file (or the error it raised)."""
    result = subprocess.run([REFERENCE_PYTHON, "-c", COUNT, *map(str, files)], env=reference_env({}),
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    return json.loads(result.stdout.strip().splitlines()[-1])


def debian_results(files: List[Path], outroot: Path) -> Dict[str, dict]:
    outroot.mkdir()
    result = subprocess.run([REFERENCE_PYTHON, "-c", DEBIAN, str(outroot), *map(str, files)],
                            env=reference_env({}), capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    return json.loads(result.stdout.strip().splitlines()[-1])


def test_minros_recovers_at_least_what_debian_recovers(tmp_path):
    require_reference()
    (tmp_path / "corpus").mkdir()
    corpus = damaged_corpus(tmp_path / "corpus")
    theirs = debian_results([d.path for d in corpus], tmp_path / "debian")
    tally: Dict[str, collections.Counter] = {"minros": collections.Counter(),
                                              "debian": collections.Counter()}
    worse = []
    ours_by_file = {}
    for d in corpus:
        outdir = tmp_path / "minros" / d.name
        outdir.mkdir(parents=True)
        ours, err = recovered(d.path, outdir)
        ours_by_file[str(outdir / d.path.name)] = ours
        one_line(err, f"rosbag reindex {d.name}")
        for cmd in ("info", "check"):
            _status, _out, err = run_cli(cmd, str(d.path))
            one_line(err, f"rosbag {cmd} {d.name}")
        _n, exc = read_all(d.path)
        assert exc is None or isinstance(exc, ROS_FAMILY), f"{d.name}: {exc!r}"
        deb = theirs[d.path.name]
        if ours < deb["recovered"]:
            worse.append((d.name, ours, deb["recovered"]))
        tally["minros"]["recovered"] += ours
        tally["minros"]["gave up"] += ours == 0 and d.keepable > 0
        tally["minros"][f"read: {type(exc).__name__ if exc else 'none'}"] += 1
        tally["debian"]["recovered"] += deb["recovered"]
        tally["debian"]["gave up"] += deb["recovered"] == 0 and d.keepable > 0
        tally["debian"][f"read: {deb['read'] or 'none'}"] += 1
        tally["debian"][f"info: {deb['info']}"] += 1
        tally["debian"][f"reindex: {deb['reindex']}"] += 1
    print(f"\n{len(corpus)} damaged bags, {sum(d.keepable for d in corpus)} messages keepable")
    for who, counts in tally.items():
        print(who, dict(sorted(counts.items())))
    assert not worse, worse
    # what minros's reindex wrote (chunks moved, index records rewritten) reads in Debian's rosbag
    assert debian_counts([Path(p) for p in ours_by_file]) == ours_by_file
    assert tally["minros"]["recovered"] > tally["debian"]["recovered"]
