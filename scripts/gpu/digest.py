#!/usr/bin/env python3
"""The SHA-256 of every file of a grid's finished runs (those with
robustness.json) but run.json, one "digest  path" line each, sorted; a
champion.json is digested without its provenance's "git_commit" line (the
build that wrote it). With --against LIST, instead the files of LIST that
GRID lacks or holds otherwise, and a count of each.

    scripts/gpu/digest.py GRID > LIST
    scripts/gpu/digest.py GRID --against LIST
"""
import hashlib
import os
import sys


def digests(grid):
    lines = {}
    for folder, subfolders, files in os.walk(os.path.join(grid, "runs")):
        subfolders.sort()
        if "robustness.json" not in files:
            continue
        for name in files:
            if name == "run.json":
                continue
            with open(os.path.join(folder, name), "rb") as f:
                data = f.read()
            if name == "champion.json":
                data = b"".join(l for l in data.splitlines(True) if b'"git_commit"' not in l)
            lines[os.path.relpath(os.path.join(folder, name), grid)] = hashlib.sha256(data).hexdigest()
    return lines


def main(argv):
    if len(argv) == 2:
        for path, digest in sorted(digests(argv[1]).items()):
            print(f"{digest}  {path}")
        return 0
    if len(argv) == 4 and argv[2] == "--against":
        have = digests(argv[1])
        missing = differing = listed = 0
        with open(argv[3]) as f:
            for line in f:
                digest, path = line.rstrip("\n").split("  ", 1)
                listed += 1
                if path not in have:
                    missing += 1
                    print(f"missing: {path}")
                elif have[path] != digest:
                    differing += 1
                    print(f"differs: {path}")
        print(f"{differing} of the {listed} listed files differ, {missing} missing")
        return 0
    sys.stderr.write(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
