"""Mutation run: plant one plausible bug at a time and see whether the tests catch it.

Usage (from the repository root, with the package's test extra installed)::

    python tools/mutation_run.py tools/mutations/*.toml [--only ID ...] [--json OUT]
                                 [--timeout 900] [--keep]

Each ``[[mutation]]`` entry of a TOML file names a source ``file``, a ``find`` text
that must occur exactly once in it, its ``replace``ment, the ``tests`` to run (the
module's own test file(s)) and ``why`` (the bug it stands for).  For every entry the
repository's files (tracked and untracked, not ignored) are copied to a private
temporary directory, the one replacement is made there, and
``python -m pytest -q -x -n 0 -p no:randomly <tests>`` runs in that copy (the copy's
``gearjax`` comes first on ``sys.path``, so the working tree is never modified and
several runs may go on at once).  Outcomes:

* ``caught``   — pytest failed (or ran past ``--timeout``: a mutant that hangs is
  caught too, and the table says so);
* ``survived`` — every test passed;
* ``invalid``  — the ``find`` text is missing or not unique, or the tests did not
  collect (a syntax or import error is not a mutation: fix the entry).

Before any mutant, the listed tests run once on the unmutated copy: a baseline that
fails makes every result of that entry meaningless, and the run stops.

JAX's persistent compilation cache is shared between the runs
(``GEARJAX_TEST_COMPILE_CACHE_DIR``, default ``.pytest_cache/d/jax-compilation`` of
this checkout): programs a mutation does not touch are not compiled again.

Kept out of CI: it runs the listed test files once per mutation.  See
docs/testing.md for the table of the last run.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def load(paths):
    out = []
    for p in paths:
        with open(p, "rb") as f:
            data = tomllib.load(f)
        for m in data.get("mutation", []):
            missing = [k for k in ("id", "file", "find", "replace", "tests") if k not in m]
            if missing:
                raise SystemExit(f"{p}: mutation {m.get('id', '?')} lacks {missing}")
            m["source"] = os.path.relpath(p, ROOT)
            out.append(m)
    ids = [m["id"] for m in out]
    dup = {i for i in ids if ids.count(i) > 1}
    if dup:
        raise SystemExit(f"duplicate mutation ids: {sorted(dup)}")
    return out


def repo_files():
    res = subprocess.run(["git", "ls-files", "-co", "--exclude-standard"], cwd=ROOT,
                         capture_output=True, text=True, check=True)
    return [f for f in res.stdout.splitlines() if os.path.isfile(os.path.join(ROOT, f))]


def make_copy(files, dest):
    for f in files:
        d = os.path.join(dest, f)
        os.makedirs(os.path.dirname(d), exist_ok=True)
        shutil.copy2(os.path.join(ROOT, f), d)


def run_tests(copy, tests, timeout, cache_dir):
    env = dict(os.environ)
    env["GEARJAX_TEST_COMPILE_CACHE_DIR"] = cache_dir
    env["PYTHONPATH"] = copy + os.pathsep + env.get("PYTHONPATH", "")
    env.pop("PYTHONSAFEPATH", None)
    cmd = [sys.executable, "-m", "pytest", "-q", "-x", "-n", "0", "-p", "no:randomly",
           "-p", "no:cacheprovider", *tests]
    t0 = time.perf_counter()
    try:
        res = subprocess.run(cmd, cwd=copy, env=env, capture_output=True, text=True,
                             timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout", time.perf_counter() - t0, ""
    tail = (res.stdout + res.stderr).strip().splitlines()
    return res.returncode, time.perf_counter() - t0, "\n".join(tail[-15:])


def first_failure(tail):
    for line in tail.splitlines():
        if line.startswith("FAILED ") or line.startswith("ERROR "):
            return line.split(" ", 1)[1].split(" - ")[0]
    return ""


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("files", nargs="+", help="TOML files of mutations")
    ap.add_argument("--only", nargs="*", default=None, help="mutation ids to run")
    ap.add_argument("--json", default=None, help="write the results as JSON here")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds per test run")
    ap.add_argument("--keep", action="store_true", help="keep the temporary copies")
    args = ap.parse_args(argv)

    muts = load(args.files)
    if args.only:
        muts = [m for m in muts if m["id"] in set(args.only)]
    cache_dir = os.environ.get("GEARJAX_TEST_COMPILE_CACHE_DIR",
                               os.path.join(ROOT, ".pytest_cache", "d", "jax-compilation"))
    os.makedirs(cache_dir, exist_ok=True)
    files = repo_files()

    # baselines: each distinct set of test files must pass unmutated
    baselines = {}
    for m in muts:
        key = tuple(m["tests"])
        if key in baselines:
            continue
        with tempfile.TemporaryDirectory(prefix="gearjax-base-") as copy:
            make_copy(files, copy)
            rc, dt, tail = run_tests(copy, list(key), args.timeout, cache_dir)
        baselines[key] = dt
        print(f"baseline {' '.join(key)}: rc={rc} ({dt:.0f} s)", file=sys.stderr, flush=True)
        if rc != 0:
            print(tail, file=sys.stderr)
            raise SystemExit(f"baseline fails for {key}: fix the tests before mutating")

    results = []
    for m in muts:
        copy = tempfile.mkdtemp(prefix="gearjax-mut-")
        try:
            make_copy(files, copy)
            path = os.path.join(copy, m["file"])
            with open(path, encoding="utf-8") as f:
                text = f.read()
            n = text.count(m["find"])
            if n != 1:
                outcome, dt, by = "invalid", 0.0, f"find text occurs {n} times"
            else:
                with open(path, "w", encoding="utf-8") as f:
                    f.write(text.replace(m["find"], m["replace"]))
                rc, dt, tail = run_tests(copy, m["tests"], args.timeout, cache_dir)
                if rc == "timeout":
                    outcome, by = "caught", "timeout"
                elif rc == 0:
                    outcome, by = "survived", ""
                elif rc in (1,):
                    outcome, by = "caught", first_failure(tail)
                else:  # 2: interrupted/collection error, 3: internal, 4: usage, 5: none
                    outcome, by = "invalid", f"pytest exit {rc}: {tail.splitlines()[-1] if tail else ''}"
        finally:
            if not args.keep:
                shutil.rmtree(copy, ignore_errors=True)
        r = dict(id=m["id"], file=m["file"], why=m.get("why", ""), tests=m["tests"],
                 outcome=outcome, caught_by=by, seconds=round(dt, 1), source=m["source"])
        results.append(r)
        print(f"{r['id']}: {outcome} {by} ({dt:.0f} s)", file=sys.stderr, flush=True)

    valid = [r for r in results if r["outcome"] != "invalid"]
    caught = sum(r["outcome"] == "caught" for r in valid)
    print("| id | file | mutation | outcome | caught by | s |")
    print("|---|---|---|---|---|---|")
    for r in results:
        print(f"| {r['id']} | {r['file']} | {r['why']} | {r['outcome']} | {r['caught_by']} "
              f"| {r['seconds']:.0f} |")
    if valid:
        print(f"\n{caught}/{len(valid)} caught ({100.0 * caught / len(valid):.0f} %)"
              f", {len(results) - len(valid)} invalid")
    if args.json:
        tmp = args.json + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            json.dump(results, f, indent=1)
        os.replace(tmp, args.json)
    return 0 if all(r["outcome"] != "invalid" for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
