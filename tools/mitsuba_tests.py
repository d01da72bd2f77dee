#!/usr/bin/env python3
"""Mitsuba 3's render-test suite through photonmap: every scene file of a
mitsuba-data checkout rendered with a time budget and judged by Mitsuba's own
acceptance test (`photonmap compare --mitsuba-test`), into a markdown table.

usage: tools/mitsuba_tests.py DATA_DIR [--photonmap BIN] [--time 30]
                              [--timeout S] [--out notes/mitsuba-tests.md]
                              [--keep DIR] [--only TEXT] [-- FLAG ...]

DATA_DIR is a mitsuba-data checkout (or its extracted copy): its scene files
are DATA_DIR/tests/scenes/*/*.xml (not those under fragments/ or include/),
each with refs/<name>_ref_rgb.exr and refs/<name>_ref_rgb_var.exr beside it,
<name> being the file's stem less its last `_<integrator>` part, as Mitsuba's
test names them (test_directional_direct.xml -> test_directional_ref_rgb.exr).
Each scene runs as

    photonmap --scene FILE.xml --time T [FLAG ...] OUT.exr

(flags after `--` are passed on), killed with its process group after
--timeout seconds of wall time (default 2T + 60), then

    photonmap compare --mitsuba-test OUT.exr REF.exr VAR.exr --json

The table (default notes/mitsuba-tests.md, written whole at the end, and
after every scene so that an interrupted run leaves what it has) says per
scene: loaded, or refused with the first line of photonmap's error (which
names file:line:column); a panic, a crash (the signal) or a timeout as such;
accepted or rejected, the share of pixel channels passing, the error of the
mean, the render's wall time. Then a summary line: N loaded, N accepted of
the scenes found. --keep DIR keeps the renders and the maps of failing
pixels (DIR/<scene>.exr, DIR/<scene>_failing.png); --only runs the scenes
whose path contains TEXT. Needs Python 3.8+ and nothing else. Exit status 0
whenever the table was written, whatever the scenes did.
"""
import argparse
import datetime
import json
import os
import shlex
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def scene_files(data_dir):
    """The suite's scene files, as Mitsuba's test lists them: the XML files
    directly inside each folder of tests/scenes (fragments/ and include/ hold
    pieces the scenes include)."""
    scenes = data_dir / "tests" / "scenes"
    if not scenes.is_dir():
        sys.exit(f"mitsuba_tests.py: {scenes} is not a directory: DATA_DIR must be a mitsuba-data checkout")
    return sorted(p for p in scenes.glob("*/*.xml") if p.is_file())


def references(scene):
    """The reference and its variance (Mitsuba's get_ref_fname, rgb variant)."""
    name = scene.stem.rsplit("_", 1)[0]
    ref = scene.parent / "refs" / f"{name}_ref_rgb.exr"
    return ref, ref.with_name(f"{name}_ref_rgb_var.exr")


def first_error_line(text, data_dir):
    """photonmap's error, one line, without its prefix and with the data
    directory's part of paths left out."""
    lines = [l.strip() for l in text.splitlines() if l.strip()]
    errors = [l for l in lines if "error:" in l] or lines
    line = errors[0] if errors else "(no message)"
    line = line.split("error: ", 1)[-1] if line.startswith("photonmap") else line
    return line.replace(str(data_dir / "tests" / "scenes") + os.sep, "")


def panic_line(text):
    for l in text.splitlines():
        if "panicked" in l:
            return l.strip()
    return "panicked"


def run(cmd, timeout):
    """Runs `cmd` in its own process group; on timeout the whole group is
    sent SIGTERM, then SIGKILL 5 s later. Returns (returncode or None on
    timeout, stdout, stderr, seconds)."""
    start = time.monotonic()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
                            start_new_session=True, text=True, errors="replace")
    try:
        out, err = proc.communicate(timeout=timeout)
        return proc.returncode, out, err, time.monotonic() - start
    except subprocess.TimeoutExpired:
        out, err = "", ""
        for sig, wait in ((signal.SIGTERM, 5), (signal.SIGKILL, None)):
            try:
                os.killpg(proc.pid, sig)
            except ProcessLookupError:
                pass
            try:
                out, err = proc.communicate(timeout=wait)
                break
            except subprocess.TimeoutExpired:
                continue
        return None, out, err, time.monotonic() - start


def signal_name(code):
    try:
        return signal.Signals(-code).name
    except ValueError:
        return f"signal {-code}"


def one_scene(scene, args, data_dir, work):
    """Renders and judges one scene; returns its row as a dict."""
    rel = scene.relative_to(data_dir / "tests" / "scenes").as_posix()
    row = {"scene": rel, "loaded": "", "accepted": "", "passing": "", "error": "", "seconds": "", "note": ""}
    key = rel[:-len(".xml")].replace("/", "__")
    out = work / f"{key}.exr"
    cmd = [args.photonmap, "--scene", str(scene), "--time", f"{args.time:g}", *args.extra, str(out)]
    code, _, err, seconds = run(cmd, args.timeout)
    row["seconds"] = f"{seconds:.1f}"
    if code is None:
        row.update(loaded="hang", note=f"timeout: killed after {args.timeout:g} s")
        return row
    if code < 0:
        row.update(loaded="crash", note=f"crashed ({signal_name(code)}): {first_error_line(err, data_dir)}")
        return row
    if code == 101 or "panicked" in err:
        row.update(loaded="panic", note=panic_line(err))
        return row
    if code != 0:
        row.update(loaded="refused", note=first_error_line(err, data_dir))
        return row
    if not out.is_file():
        row.update(loaded="yes", note="exit 0 but no image written")
        return row
    row["loaded"] = "yes"
    ref, var = references(scene)
    missing = [p.name for p in (ref, var) if not p.is_file()]
    if missing:
        row["note"] = "no reference: " + ", ".join(missing)
        return row
    compare = [args.photonmap, "compare", "--mitsuba-test", str(out), str(ref), str(var), "--json"]
    if args.keep:
        compare += ["--fail-map", str(work / f"{key}_failing.png")]
    code, stdout, err, _ = run(compare, 300)
    if code in (0, 1):
        try:
            v = json.loads(stdout)
        except ValueError:
            row["note"] = f"compare printed no verdict (exit {code})"
            return row
        row["accepted"] = "yes" if v["accepted"] else "no"
        row["passing"] = f"{100 * v['fraction_passing']:.2f}%"
        e = v.get("mean_relative_error")
        row["error"] = "undefined" if e is None else f"{100 * e:.2f}%"
        if v.get("non_finite"):
            row["note"] = f"{v['non_finite']} non-finite values in the image"
    elif code is None:
        row["note"] = "compare: timeout"
    elif code < 0 or code == 101:
        row["note"] = f"compare crashed (exit {code}): {first_error_line(err, data_dir)}"
    else:
        row["note"] = "compare: " + first_error_line(err, data_dir).replace(str(out), "the render")
    return row


def cell(text):
    text = str(text).replace("|", "\\|").replace("\n", " ")
    return text if len(text) <= 200 else text[:197] + "..."


def version(photonmap):
    try:
        v = subprocess.run([photonmap, "--version"], capture_output=True, text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        v = "photonmap (version unknown)"
    try:
        commit = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True,
                                text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        commit = ""
    return f"{v} at {commit}" if commit else v


def table(rows, total, args, started, finished):
    loaded = sum(r["loaded"] == "yes" for r in rows)
    accepted = sum(r["accepted"] == "yes" for r in rows)
    extra = " " + " ".join(shlex.quote(a) for a in args.extra) if args.extra else ""
    lines = [
        "# Mitsuba 3's render tests",
        "",
        "The scenes of Mitsuba 3's render-test suite (`tests/scenes/*/*.xml` of the",
        "mitsuba-renderer/mitsuba-data repository), each rendered by photonmap as",
        f"`photonmap --scene FILE.xml --time {args.time:g}{extra} OUT.exr` and judged by Mitsuba's own",
        "acceptance test (`photonmap compare --mitsuba-test OUT.exr REF.exr VAR.exr`, after",
        "src/render/tests/test_renders.py in mitsuba-renderer/mitsuba3: images in XYZ,",
        "the reference's variance floored at 1e-4, z = |image - reference| * sqrt(spp / variance)",
        "with spp = 2,000,000 / pixels, a pixel channel passing when its two-sided p-value",
        "exceeds the Sidak level 1 - 0.99^(1/pixels), accepted when 99.75% of them pass",
        "and the image is finite). Written by `tools/mitsuba_tests.py DATA_DIR` (its",
        "docstring says how); regenerate it rather than edit it.",
        "",
        "Columns: *loaded* is yes, refused (with the first line of the error, which names",
        "file:line:column), panic, crash or hang (killed after the timeout); *passing* is",
        "the share of pixel channels whose p-value exceeds the level (99.75% needed);",
        "*error* is the error of the image's mean against the reference's (XYZ);",
        "*s* is the render's wall time, loading included.",
        "",
        f"Run {started:%Y-%m-%d %H:%M} to {finished:%H:%M} UTC with {version(args.photonmap)},",
        f"--time {args.time:g} s, timeout {args.timeout:g} s per scene.",
        "",
        f"**{loaded} loaded, {accepted} accepted of {total}**"
        + (f" ({len(rows)} run so far)" if len(rows) < total else ""),
        "",
        "| scene | loaded | accepted | passing | error | s | note |",
        "|---|---|---|---|---|---:|---|",
    ]
    for r in rows:
        lines.append("| " + " | ".join(cell(r[k]) for k in
                                        ("scene", "loaded", "accepted", "passing", "error", "seconds", "note")) + " |")
    return "\n".join(lines) + "\n"


def write_atomically(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def main():
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        i = argv.index("--")
        argv, extra = argv[:i], argv[i + 1:]
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("data_dir", type=Path, help="a mitsuba-data checkout (holding tests/scenes)")
    ap.add_argument("--photonmap", default=str(REPO / "target" / "release" / "photonmap"), help="the binary")
    ap.add_argument("--time", type=float, default=30.0, help="photonmap's --time per scene, seconds (default 30)")
    ap.add_argument("--timeout", type=float, help="wall-clock limit per scene, seconds (default 2 * time + 60)")
    ap.add_argument("--out", type=Path, default=REPO / "notes" / "mitsuba-tests.md", help="the table")
    ap.add_argument("--keep", type=Path, help="keep renders and failing-pixel maps in this directory")
    ap.add_argument("--only", help="run only the scenes whose path contains this")
    args = ap.parse_args(argv)
    args.extra = extra
    if args.timeout is None:
        args.timeout = 2 * args.time + 60
    if not (args.time > 0 and args.timeout > 0):
        sys.exit("mitsuba_tests.py: --time and --timeout must be positive")
    if not os.access(args.photonmap, os.X_OK):
        sys.exit(f"mitsuba_tests.py: {args.photonmap} is not an executable (build it: cargo build --release)")
    data_dir = args.data_dir.resolve()
    scenes = scene_files(data_dir)
    total = len(scenes)
    if args.only:
        scenes = [s for s in scenes if args.only in s.relative_to(data_dir).as_posix()]
    if not scenes:
        sys.exit(f"mitsuba_tests.py: no scene files under {data_dir / 'tests' / 'scenes'}")
    started = datetime.datetime.now(datetime.timezone.utc)
    rows = []
    with tempfile.TemporaryDirectory(prefix="mitsuba-tests-") as tmp:
        work = args.keep or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        for i, scene in enumerate(scenes, 1):
            row = one_scene(scene, args, data_dir, work)
            rows.append(row)
            print(f"[{i}/{len(scenes)}] {row['scene']}: {row['loaded']} {row['accepted']} {row['passing']} "
                  f"{row['seconds']} s {row['note'][:120]}", flush=True)
            now = datetime.datetime.now(datetime.timezone.utc)
            write_atomically(args.out, table(rows, total if not args.only else len(scenes), args, started, now))
    loaded = sum(r["loaded"] == "yes" for r in rows)
    accepted = sum(r["accepted"] == "yes" for r in rows)
    print(f"{loaded} loaded, {accepted} accepted of {len(rows)}; table: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
