#!/usr/bin/env python3
"""The project's headline figures, measured and written to one file.

    python3 tools/results.py [--only PART ...] [--skip PART ...] [--runs N]
                             [--quote] [--out notes/results.csv]

README.md and notes/*.md quote figures from notes/results.csv: a quoted
figure is a number followed by a marker naming its key, `7.8 s<!--r:default.wall_s-->`
(an HTML comment: invisible where Markdown is rendered). tests/results.rs fails
when a quoted number differs from the file's value rounded to the decimals it
is written with. `--quote` rewrites every quoted number from the file (same
decimals), so a re-measurement updates README and notes in one step.

Parts (all by default; each row records the command, the commit, the machine
with its load average, and the date it was measured):

  default   the default command (`photonmap --photons 1e6 OUT.exr`), seeds
            1..N (--runs, default 3), scored against tests/data/default_e1_200.exr
            with --reference: median wall time, RMSE, caustic-window RMSE,
            mean against the reference (~10 s a run on an idle 2-core VM).
  rays      `cargo run --release --example floors`: ns per ray of the
            default room through the scene (random rays in the room and the
            camera's primary rays, closest hit and occlusion); and `--example
            raycast`: random rays through the renderer's accelerator, a BVH of
            everything and the flat loop (~1 minute both).
  tests     the number of tests `cargo test --release` runs (`-- --list`;
            builds the tests if they are not built).
  suite     copied from notes/suite.csv (written by `cargo run --release
            --example suite`, which takes an hour): each scene's default and
            60 s renders and Mitsuba's at equal time; commit and date are
            those of suite.csv's last commit.
  mitsuba   copied from notes/mitsuba-tests.md (tools/mitsuba_tests.py):
            scenes loaded and accepted by Mitsuba's acceptance test.
  build     slow, not in the default set (`--only build` or `--with build`):
            a fresh clone of HEAD built in an empty target directory,
            `cargo build --release`, then `cargo test --release --no-run`,
            then the tests run (`cargo test --release`), each timed.

Rows of parts not run this time are kept from the file as it was, so a quick
rerun (`--skip rays --runs 1`) takes a minute. Run it on a quiet machine
for figures to publish: the load average is recorded with each row.
"""

import argparse
import csv
import datetime
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PARTS = ["default", "rays", "tests", "suite", "mitsuba"]
SLOW = ["build"]
FIELDS = ["key", "value", "unit", "command", "commit", "machine", "date"]
# The marker that follows a quoted figure, and the number just before it
# (optionally in **bold**, with a unit or % between). tests/results.rs reads
# the same pattern.
MARKER = re.compile(r"<!--r:([A-Za-z0-9_.\-]+)-->")
NUMBER = re.compile(r"[-+]?\d[\d,]*(?:\.\d+)?")


def git(*args):
    return subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True, check=True).stdout.strip()


def machine():
    model = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    load = os.getloadavg()[0]
    return f"{os.cpu_count()}-core {model}; load {load:.1f}"


def now():
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")


def clean(text):
    # The file is split on commas by tests/results.rs: none in a field.
    return str(text).replace(",", ";").replace('"', "'").replace("\n", " ")


class Results:
    def __init__(self, commit, where):
        self.rows = []
        self.commit = commit
        self.where = where

    def add(self, key, value, unit, command, commit=None, date=None, where=None):
        self.rows.append(
            {
                "key": key,
                "value": value,
                "unit": unit,
                "command": clean(command),
                "commit": commit or self.commit,
                "machine": clean(where or self.where),
                "date": date or now(),
            }
        )


def release_binary():
    subprocess.run(["cargo", "build", "--release", "--quiet", "--bin", "photonmap"], cwd=ROOT, check=True)
    return os.path.join(ROOT, "target", "release", "photonmap")


def part_default(res, runs):
    exe = release_binary()
    reference = os.path.join(ROOT, "tests", "data", "default_e1_200.exr")
    walls, scores = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(1, runs + 1):
            out = os.path.join(tmp, "out.exr")
            cmd = [exe, "--photons", "1e6", out, "--seed", str(seed), "--reference", reference, "-q"]
            t = time.perf_counter()
            p = subprocess.run(cmd, capture_output=True, text=True, check=True)
            walls.append(time.perf_counter() - t)
            scores.append(json.loads(p.stdout))
            print(f"  default, seed {seed}: {walls[-1]:.2f} s, {p.stdout.strip()}", file=sys.stderr)
    seeds = f"seeds 1-{runs}" if runs > 1 else "seed 1"
    command = f"photonmap --photons 1e6 OUT.exr --seed S --reference tests/data/default_e1_200.exr ({seeds}; median)"
    res.add("default.wall_s", f"{statistics.median(walls):.3f}", "s", command)
    res.add("default.runs", runs, "runs", command)
    for s in scores:
        s["mean_error_pct"] = (s["mean_x"] / s["mean_r"] - 1.0) * 100.0
    for key, name, unit, fmt in [
        ("default.rmse", "rmse", "", "{:.6f}"),
        ("default.caustic_rmse", "caustic_rmse", "", "{:.6f}"),
        ("default.mean_error_pct", "mean_error_pct", "%", "{:.3f}"),
    ]:
        res.add(key, fmt.format(statistics.median(s[name] for s in scores)), unit, command)


def part_floors(res):
    p = subprocess.run(
        ["cargo", "run", "--release", "--quiet", "--example", "floors"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    command = "cargo run --release --example floors (one thread)"
    wanted = {
        "floors.random_closest_ns": r"closest hit, random rays in the room: (\d+) ns",
        "floors.random_occlusion_ns": r"occlusion to t = 3, random rays in the room: (\d+) ns",
        "floors.primary_closest_ns": r"closest hit, primary camera rays: (\d+) ns",
    }
    for key, pattern in wanted.items():
        m = re.search(pattern, p.stdout)
        if not m:
            sys.exit(f"results: the floors example printed nothing like '{pattern}'")
        res.add(key, m.group(1), "ns", command)


def part_raycast(res):
    p = subprocess.run(
        ["cargo", "run", "--release", "--quiet", "--example", "raycast"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    found = {}
    for line in p.stdout.splitlines():
        m = re.match(r"(.+?): ([\d.]+) ns/ray", line)
        if m:
            found[m.group(1)] = m.group(2)
    command = "cargo run --release --example raycast (2e6 random rays in the room; one thread)"
    for key, name in [
        ("raycast.renderer_ns", "enclosure + bvh (the renderer's)"),
        ("raycast.bvh_ns", "bvh, watertight"),
        ("raycast.flat_ns", "flat, watertight"),
    ]:
        if name not in found:
            sys.exit(f"results: the raycast example printed no line for '{name}'")
        res.add(key, found[name], "ns", command)


def part_tests(res):
    p = subprocess.run(
        ["cargo", "test", "--release", "--quiet", "--", "--list"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    n = sum(1 for line in p.stdout.splitlines() if line.endswith(": test"))
    res.add("tests.count", n, "tests", "cargo test --release -- --list (lines ending ': test')")


def part_suite(res):
    path = os.path.join(ROOT, "notes", "suite.csv")
    commit = git("log", "-1", "--format=%h", "--", "notes/suite.csv")
    date = git("log", "-1", "--format=%cd", "--date=format-local:%Y-%m-%d %H:%M UTC", "--", "notes/suite.csv")
    # The suite names its machine in notes/suite.md; suite.csv does not.
    where = "see notes/suite.md"
    command = "cargo run --release --example suite (copied from notes/suite.csv)"
    units = {"seconds": "s", "count": "", "bias": "", "caustic_bias": "", "rmse": "", "caustic_rmse": ""}
    with open(path) as f:
        for row in csv.DictReader(f):
            for field, unit in units.items():
                if row.get(field, "") != "":
                    res.add(f"suite.{row['scene']}.{row['run']}.{field}", row[field], unit, command, commit, date, where)
            # Biases as the notes write them, in percent.
            for field in ["bias", "caustic_bias"]:
                if row.get(field, "") != "":
                    pct = f"{float(row[field]) * 100:.3f}"
                    res.add(f"suite.{row['scene']}.{row['run']}.{field}_pct", pct, "%", command, commit, date, where)


def part_mitsuba(res):
    path = os.path.join(ROOT, "notes", "mitsuba-tests.md")
    with open(path) as f:
        text = f.read()
    m = re.search(r"\*\*(\d+) loaded, (\d+) accepted of (\d+)\*\*", text)
    if not m:
        sys.exit("results: notes/mitsuba-tests.md has no '**N loaded, N accepted of N**' line")
    commit = git("log", "-1", "--format=%h", "--", "notes/mitsuba-tests.md")
    run = re.search(r"Run (\d{4}-\d\d-\d\d \d\d:\d\d)", text)
    date = f"{run.group(1)} UTC" if run else now()
    command = "python3 tools/mitsuba_tests.py DATA --time 30 (copied from notes/mitsuba-tests.md)"
    where = "see notes/mitsuba-tests.md"
    res.add("mitsuba.loaded", m.group(1), "scenes", command, commit, date, where)
    res.add("mitsuba.accepted", m.group(2), "scenes", command, commit, date, where)
    res.add("mitsuba.scenes", m.group(3), "scenes", command, commit, date, where)


def part_build(res):
    with tempfile.TemporaryDirectory() as tmp:
        clone = os.path.join(tmp, "clone")
        subprocess.run(["git", "clone", "-q", ROOT, clone], check=True)
        subprocess.run(["git", "-C", clone, "checkout", "-q", git("rev-parse", "HEAD")], check=True)
        env = dict(os.environ, CARGO_TARGET_DIR=os.path.join(tmp, "target"))
        steps = [
            ("build.render_s", ["cargo", "build", "--release", "--quiet"], "cargo build --release (fresh clone; empty target)"),
            ("build.tests_s", ["cargo", "test", "--release", "--quiet", "--no-run"], "then cargo test --release --no-run"),
            ("build.test_run_s", ["cargo", "test", "--release", "--quiet"], "then cargo test --release (tests built)"),
        ]
        for key, cmd, command in steps:
            t = time.perf_counter()
            subprocess.run(cmd, cwd=clone, env=env, check=True, stdout=subprocess.DEVNULL)
            res.add(key, f"{time.perf_counter() - t:.0f}", "s", command)
            print(f"  {key}: {time.perf_counter() - t:.0f} s", file=sys.stderr)


def read(path):
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def quoted_files():
    files = [os.path.join(ROOT, "README.md")]
    for base, _, names in os.walk(os.path.join(ROOT, "notes")):
        files += [os.path.join(base, n) for n in sorted(names) if n.endswith(".md")]
    return files


def quote(values):
    """Rewrites each number that a marker follows with the file's value, at
    the decimals it was written with."""
    for path in quoted_files():
        with open(path) as f:
            text = f.read()
        out, last = [], 0
        for m in MARKER.finditer(text):
            key = m.group(1)
            line_start = text.rfind("\n", 0, m.start()) + 1
            before = list(NUMBER.finditer(text, line_start, m.start()))
            if key not in values or not before or m.start() - before[-1].end() > 4:
                print(f"{os.path.relpath(path, ROOT)}: marker {key}: no value or no number before it", file=sys.stderr)
                continue
            n = before[-1]
            written = n.group(0)
            decimals = len(written.split(".")[1]) if "." in written else 0
            new = f"{float(values[key]):,.{decimals}f}" if "," in written else f"{float(values[key]):.{decimals}f}"
            if written.startswith("+") and not new.startswith("-"):
                new = "+" + new
            out.append(text[last : n.start()])
            out.append(new)
            last = n.end()
        out.append(text[last:])
        new_text = "".join(out)
        if new_text != text:
            tmp = path + ".tmp"
            with open(tmp, "w") as f:
                f.write(new_text)
            os.replace(tmp, path)
            print(f"quoted: {os.path.relpath(path, ROOT)}", file=sys.stderr)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", action="append", choices=PARTS + SLOW, help="run only this part (repeatable)")
    ap.add_argument("--skip", action="append", default=[], choices=PARTS, help="skip this part (repeatable)")
    ap.add_argument("--with", dest="extra", action="append", default=[], choices=SLOW, help="add a slow part")
    ap.add_argument("--runs", type=int, default=3, help="default-command runs (seeds 1..N; median)")
    ap.add_argument("--quote", action="store_true", help="rewrite the quoted figures of README.md and notes/")
    ap.add_argument("--out", default=os.path.join(ROOT, "notes", "results.csv"))
    args = ap.parse_args()
    parts = args.only or [p for p in PARTS if p not in args.skip] + args.extra
    if args.runs < 1:
        sys.exit("results: --runs must be at least 1")

    dirty = git("status", "--porcelain", "--untracked-files=no")
    commit = git("rev-parse", "--short", "HEAD") + ("+dirty" if dirty else "")
    res = Results(commit, machine())
    for part in parts:
        print(f"results: {part}", file=sys.stderr)
        if part == "default":
            part_default(res, args.runs)
        elif part == "rays":
            part_floors(res)
            part_raycast(res)
        elif part == "tests":
            part_tests(res)
        elif part == "suite":
            part_suite(res)
        elif part == "mitsuba":
            part_mitsuba(res)
        elif part == "build":
            part_build(res)

    # Keep the rows of the parts not run this time.
    fresh = {r["key"] for r in res.rows}
    prefixes = {"rays": ("floors.", "raycast.")}
    ran = tuple(x for p in parts for x in prefixes.get(p, (f"{p}.",)))
    kept = [r for r in read(args.out) if r["key"] not in fresh and not r["key"].startswith(ran)]
    rows = sorted(kept + res.rows, key=lambda r: r["key"])
    tmp = args.out + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS, lineterminator="\n", quoting=csv.QUOTE_NONE, escapechar=None)
        w.writeheader()
        for r in rows:
            w.writerow({k: r[k] for k in FIELDS})
    os.replace(tmp, args.out)
    print(f"results: {len(res.rows)} rows measured, {len(kept)} kept, in {os.path.relpath(args.out, ROOT)}", file=sys.stderr)
    if args.quote:
        quote({r["key"]: r["value"] for r in rows})


if __name__ == "__main__":
    main()
