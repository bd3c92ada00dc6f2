#!/usr/bin/python3
"""The checks of scripts/soak, on its soak.csv and the saved-against-received comparison.

Prints one line per figure and per check; exits 1 when a check fails.
"""
import argparse
import csv
import os
import re
import sys


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--csv", required=True)
    parser.add_argument("--settled-s", type=float, required=True,
                        help="when the run has settled (the end of its first loops)")
    parser.add_argument("--drive-s", type=float, required=True,
                        help="how long the robot drove: later samples see the final save")
    parser.add_argument("--compare", required=True, help="semap-export --compare output")
    parser.add_argument("--map", required=True, help="the map saved at exit (.smap)")
    parser.add_argument("--listener", required=True, help="semap-map-listener output")
    args = parser.parse_args()

    # At the end the robot reads the whole map back from the log to save it: not the long day.
    rows = [r for r in csv.DictReader(open(args.csv))
            if r["rss_mib"] and float(r["t_s"]) < args.drive_s - 5]
    failures = []

    def check(ok, text):
        print(("PASS " if ok else "FAIL ") + text)
        if not ok:
            failures.append(text)

    after = [r for r in rows if float(r["t_s"]) >= args.settled_s]
    check(len(after) >= 3, f"{len(after)} samples once settled ({args.settled_s:.0f} s)")
    if not after:
        return 1
    rss_loop = float(after[0]["rss_mib"])
    rss_max = max(float(r["rss_mib"]) for r in after)
    rss_end = float(rows[-1]["rss_mib"])
    print(f"rss: {rss_loop:.1f} MiB when settled, {rss_max:.1f} MiB at most "
          f"after it, {rss_end:.1f} MiB at the end ({len(rows)} samples, {rows[-1]['t_s']} s)")
    check(rss_max <= 1.10 * rss_loop, f"RSS once settled within 10 % of {rss_loop:.1f} MiB "
          f"(max {rss_max:.1f}, {100 * (rss_max / rss_loop - 1):+.1f} %)")

    map_mib = os.path.getsize(args.map) / 1048576
    log_max = max(float(r["log_mib"]) for r in after)
    log_end = float(rows[-1]["log_mib"])
    print(f"checkpoint log: {float(after[0]['log_mib']):.2f} MiB once settled, "
          f"{log_max:.2f} MiB at most, {log_end:.2f} MiB at the end; saved map {map_mib:.2f} MiB")
    # Compaction rewrites the log once it holds three times its live blocks; a checkpoint
    # interval more may be on top.
    check(log_max <= 4.0 * map_mib, f"checkpoint log at most 4x the map ({log_max:.2f} MiB "
          f"against {map_mib:.2f} MiB)")

    cpu = [float(r["cpu_percent"]) for r in after if r["cpu_percent"]]
    load = [float(r["load1"]) for r in after]
    drops = int(rows[-1]["health_drops"])
    print(f"cpu: {sum(cpu) / len(cpu):.0f} % of one core on average once settled, "
          f"load1 {min(load):.1f}..{max(load):.1f}; drops in health {drops}; checkpoint failures "
          f"{rows[-1]['checkpoint_failures']}")
    for stage in ("perception", "mapping"):
        p50 = sorted(float(r[f"{stage}_p50_ms"]) for r in after)
        p99 = sorted(float(r[f"{stage}_p99_ms"]) for r in after)
        print(f"{stage} latency: p50 {p50[len(p50) // 2]:.0f} ms (median of samples), "
              f"p99 {p99[len(p99) // 2]:.0f} ms median, {p99[-1]:.0f} ms worst")
    check(rows[-1]["checkpoint_failures"] == "0", "no checkpoint failed")

    text = open(args.compare).read()
    value = {k: float(v) for k, v in re.findall(r"^(\w+) ([0-9.]+)$", text, re.M)}
    saved, received, same = (int(value.get(k, -1)) for k in
                             ("occupied_cells", "received_cells", "same_cells"))
    final = re.findall(r"^final: blocks (\d+) accepted \d+ rejected (\d+)", open(args.listener).read(),
                       re.M)
    blocks, rejected = (int(x) for x in final[-1]) if final else (-1, -1)
    print(f"map: listener {blocks} blocks ({rejected} rejected); "
          f"occupied cells saved {saved}, received {received}, the same {same}")
    check(blocks > 0 and rejected == 0, "the listener took every block it received")
    check(saved > 0 and saved == received == same,
          "the map reloaded from disk equals the live map (every occupied cell, same class)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
