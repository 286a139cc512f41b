#!/usr/bin/env python3
"""The device check's section of docs/PERFORMANCE.md (scripts/gpu-check.sh).

  gpu_check_report.py --logs DIR --device TEXT --driver TEXT --validation 0|1 --commit REV
                      --command TEXT        prints the section, made from the programs' logs
  gpu_check_report.py --insert SECTION FILE replaces FILE's text between the gpu-check markers
                                            with SECTION (appends a heading and markers first
                                            when FILE has none)
"""
import argparse
import datetime
import json
import os
import re
import sys

BEGIN, END = "<!-- gpu-check:begin -->", "<!-- gpu-check:end -->"
SERIES = re.compile(r"^(?P<label>\S.*?)\s+frame wall median\s+(?P<wall>[\d.]+) ms\s+p99\s+"
                    r"(?P<p99>[\d.]+) ms.*gpu median\s+(?P<gpu>[\d.]+) ms")
PASS = re.compile(r"^    (?P<name>\w+)\s+median\s+(?P<median>[\d.]+) ms\s+p99\s+(?P<p99>[\d.]+) ms")


def read(path):
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            return f.read()
    except OSError:
        return ""


def series(text):
    """{label: {"wall", "p99", "gpu", "passes": {name: (median, p99)}}} of a skyd_bench log."""
    out, current = {}, None
    for line in text.splitlines():
        m = SERIES.match(line)
        if m:
            current = {"wall": float(m["wall"]), "p99": float(m["p99"]), "gpu": float(m["gpu"]),
                       "passes": {}}
            out[m["label"].strip()] = current
            continue
        m = PASS.match(line)
        if m and current is not None:
            current["passes"][m["name"]] = (float(m["median"]), float(m["p99"]))
    return out


def top_passes(passes, n=4):
    ranked = sorted(passes.items(), key=lambda kv: -kv[1][0])[:n]
    return ", ".join(f"{name} {median:.2f}" for name, (median, _) in ranked)


def section(a):
    logs = a.logs
    lines = [f"### {a.device}, {datetime.date.today().isoformat()}", "",
             f"`{a.command}` at {a.commit}; driver {a.driver}; render suites with the validation "
             f"layer {'on' if a.validation == '1' else 'off (not installed)'}, benches without "
             f"it.", ""]
    results = [l.split("|") for l in read(os.path.join(logs, "results.txt")).splitlines() if l]
    tests = [r for r in results if not r[0].startswith(("bench_", "stream_"))]
    if tests:
        lines += ["| render suite | result | seconds |", "| --- | --- | --- |"]
        lines += [f"| {name} | {result} | {secs} |" for name, result, secs in tests]
        lines.append("")
    sky = series(read(os.path.join(logs, "bench_sky.txt")))
    clouds = series(read(os.path.join(logs, "bench_clouds.txt")))
    frames = [k for k in sky if k.startswith("frame ")]
    if frames:
        lines += ["| size | sky + AP, GPU median / p99 (ms) | with clouds, GPU median / p99 (ms) "
                  "| largest passes with clouds (median ms) |", "| --- | --- | --- | --- |"]
        for k in frames:
            s, c = sky[k], clouds.get(k)
            cloudy = f"{c['gpu']:.2f} / {c['p99']:.2f}" if c else "not run"
            lines.append(f"| {k[6:]} | {s['gpu']:.2f} / {s['p99']:.2f} | {cloudy} | "
                         f"{top_passes(c['passes']) if c else ''} |")
        lines.append("")
    rebuild = sky.get("atmosphere LUT rebuild")
    text = read(os.path.join(logs, "bench_sky.txt"))
    trivial = re.search(r"trivial write 1280x720: ([\d.]+) ms; rebuild/trivial: ([\d.]+)x", text)
    if rebuild:
        passes = ", ".join(f"{n} {m:.2f}" for n, (m, _) in rebuild["passes"].items())
        ratio = f"; {trivial[2]}x a 1280x720 trivial write" if trivial else ""
        lines += [f"Atmosphere LUT rebuild: GPU median {rebuild['gpu']:.2f} ms ({passes}){ratio}.",
                  ""]
    auto_text = read(os.path.join(logs, "bench_clouds_auto.txt"))
    auto = series(auto_text)
    levels = [f"{level}, {steps} steps" if steps else level
              for level, steps in re.findall(r"traced at (\w+)(?: with (\d+) march steps)?",
                                             auto_text)]
    auto_frames = [k for k in auto if k.startswith("frame ")]
    if auto_frames:
        lines += ["| size | clouds.quality.resolution auto, 2 ms budget: GPU median / p99 (ms) "
                  "| level reached, march steps |", "| --- | --- | --- |"]
        for i, k in enumerate(auto_frames):
            level = levels[i] if i < len(levels) else "?"
            lines.append(f"| {k[6:]} | {auto[k]['gpu']:.2f} / {auto[k]['p99']:.2f} | {level} |")
        lines.append("")
    m = re.search(r"table complete ([\d.]+) s, faded in ([\d.]+) s", read(
        os.path.join(logs, "bench_converge.txt")))
    if m:
        lines += [f"Converged multiple scattering at 1280x720, frames at 60 fps (the daemon's "
                  f"LUT budget): complete {m[1]} s, faded in {m[2]} s after the change.", ""]
    streams = []
    for name in sorted(os.listdir(logs)):
        if not name.startswith("stream_"):
            continue
        for line in read(os.path.join(logs, name)).splitlines():
            if line.startswith('{"bench":"serve"'):
                streams.append(json.loads(line))
    if streams:
        lines += ["| stream | clients | mean fps per client | total fps |", "| --- | --- | --- | --- |"]
        for s in streams:
            for r in s["results"]:
                lines.append(f"| {s['width']}x{s['height']} {s.get('format', 'png')} at "
                             f"{s['fps']:g} fps | {r['clients']} | {r['mean_fps']:.1f} | "
                             f"{r['total_fps']:.1f} |")
        lines.append("")
    failed = [r for r in results if r[1] != "passed"]
    if failed:
        lines += ["Did not pass: " + ", ".join(f"{n} ({r})" for n, r, _ in failed) +
                  f" (logs in {logs}).", ""]
    return "\n".join(lines)


def insert(section_path, doc_path):
    body = read(section_path).rstrip("\n")
    doc = read(doc_path)
    if BEGIN not in doc or END not in doc:
        doc = doc.rstrip("\n") + ("\n\n## Device check (scripts/gpu-check.sh)\n\n"
                                  "Written by `scripts/gpu-check.sh` on the machine it ran on; "
                                  "run it again to replace it.\n\n" + BEGIN + "\n" + END + "\n")
    head, rest = doc.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    with open(doc_path, "w", encoding="utf-8") as f:
        f.write(head + BEGIN + "\n" + body + "\n" + END + tail)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--logs")
    p.add_argument("--device", default="unknown")
    p.add_argument("--driver", default="unknown")
    p.add_argument("--validation", default="0")
    p.add_argument("--commit", default="unknown")
    p.add_argument("--command", default="scripts/gpu-check.sh")
    p.add_argument("--insert", nargs=2, metavar=("SECTION", "FILE"))
    a = p.parse_args()
    if a.insert:
        insert(*a.insert)
        return 0
    if not a.logs:
        p.error("--logs or --insert")
    print(section(a))
    return 0


if __name__ == "__main__":
    sys.exit(main())
