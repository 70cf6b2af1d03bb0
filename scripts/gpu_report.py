#!/usr/bin/env python3
"""Markdown pages of scripts/gpu.sh's own parts, from the files fluidform writes.

  gpu_report.py character SUMMARY_JSON COMMAND   -> the liquid character's page
  gpu_report.py dambreak STABILITY_JSON COMMAND  -> the 1M DFSPH dam break's page
  gpu_report.py state STATE_CSV|none SPANS OUT   -> the device's state per step
Prints the page on stdout. `state` reads nvidia-smi's log (gpu.sh's device-state.csv) and
the steps' spans (name|start|end, epoch seconds), prints a table of each step's clock,
power and throttle ranges, and appends the same line to each step's page in OUT.
"""
import json
import sys


def num(v, digits=3):
    return "-" if v is None else f"{v:.{digits}f}"


def character(path, command):
    j = json.load(open(path))
    stats = j["stats"]
    render = stats.get("render", {}).get("settings", {})
    print("# The default liquid character\n")
    print(f"Made by `{command}`.\n")
    prov = j.get("provenance")
    if prov:
        d = j["device"]
        print(f"Measured {prov['date']} on {d['name']} ({d['driver']}), commit {prov['commit']}, "
              f"{prov['rustc']}.\n")
    print(f"{stats['particles']} particles, {render.get('width')}x{render.get('height')}, "
          f"{j['frames']} frames ({stats['steps']} SPH steps, {num(stats['simulated_seconds'], 2)} "
          f"simulated s), list {render.get('list')}, material {render.get('material')}.\n")
    f = j["frame_ms"]
    print(f"GPU frame time: median **{num(f['median'])} ms** [{num(f['min'])}, {num(f['max'])}], "
          f"{num(j['fps'], 1)} fps.\n")
    print("| pass | median ms | min | max |\n|---|---|---|---|")
    for name, s in j["pass_ms"].items():
        print(f"| {name} | {num(s['median'])} | {num(s['min'])} | {num(s['max'])} |")
    print()
    for t in stats.get("control", {}).get("targets", []):
        fid = t.get("fidelity") or {}
        print(f"Fidelity of '{t['target']}' ({t['control_particles']} control particles) over "
              f"the frames from {num(fid.get('from'), 2)} s (the README's fidelity metrics):\n")
        print("| metric | mean | min |\n|---|---|---|")
        for k, v in fid.items():
            if isinstance(v, dict):
                print(f"| {k} | {num(v.get('mean'))} | {num(v.get('min'))} |")
        print(f"| time to 90% fill s | {num(t.get('time_to_90'), 2)} | |")
        print()
    print(f"NaN particles {stats['nan']}, outside the domain {stats['outside_domain']}, "
          f"mean density {num(stats['density_mean_over_rest'], 4)} of rest.\n")
    print("![the last saved frame](character.png)\n")
    d = j["device"]
    print(f"Device: {d['name']} ({d['type']}), driver {d['driver']}, Vulkan {d['api']}.")


def dambreak(path, command):
    j = json.load(open(path))
    sim, gpu, wall = j["simulated_seconds"], j["gpu_seconds"], j["wall_seconds"]
    e = j.get("density_error") or {}
    unstable = j.get("unstable")
    print(f"# The DFSPH dam break at {j['particles']} particles, rendering off\n")
    print(f"Made by `{command}`.\n")
    prov = j.get("provenance")
    if prov:
        print(f"Measured {prov['date']}, commit {prov['commit']}, {prov['rustc']}.\n")
    print(f"{j['particles']} particles, solver {j['fluid']['solver']}, {j['steps']} steps.\n")
    print(f"- simulated: **{num(sim, 2)} s**; "
          f"{'**unstable**: ' + unstable if unstable else 'stable to the end'}")
    print(f"- simulated seconds per GPU second: **{num(sim / gpu if gpu else None, 4)}**; "
          f"per wall second: {num(sim / wall if wall else None, 4)}")
    print(f"- mean density error {num(100 * e.get('mean', float('nan')), 3)}%, "
          f"{num(e.get('iterations_mean'), 1)} pressure iterations a step on average")
    print(f"- mean density within 5% of rest: {j.get('mean_density_within_5_percent')}\n")
    print("| step | time s | NaN | outside | density / rest | max speed m/s |\n|---|---|---|---|---|---|")
    for c in j["checkpoints"]:
        print(f"| {c['step']} | {num(c['time'], 2)} | {c['nan']} | {c['outside_domain']} | "
              f"{num(c['density_mean_over_rest'], 4)} | {num(c['max_speed'], 2)} |")


# nvidia-smi's clocks_event_reasons (clocks_throttle_reasons) bits.
REASONS = {
    0x1: "idle", 0x2: "application clocks", 0x4: "software power cap",
    0x8: "hardware slowdown", 0x10: "sync boost", 0x20: "software thermal",
    0x40: "hardware thermal", 0x80: "power brake", 0x100: "display clock",
}

# The page each gpu.sh step writes.
PAGES = {
    "bench-primitives": "primitives.md", "bench-sph": "sph.md", "bench-render": "render.md",
    "bench-solvers": "solvers.md", "character": "character.md", "dambreak": "dambreak.md",
}


def page_of(step):
    step = step.removesuffix(" again")
    if step.startswith("experiment-"):
        return step.removeprefix("experiment-") + ".md"
    return PAGES.get(step)


def samples(path):
    """(epoch s, sm MHz, mem MHz, power W, temp C, reasons bitmask, pstate) per line."""
    import datetime
    out = []
    for line in open(path):
        c = [x.strip() for x in line.split(",")]
        if len(c) < 7 or c[0].startswith("timestamp"):
            continue
        try:
            t = datetime.datetime.strptime(c[0], "%Y/%m/%d %H:%M:%S.%f").timestamp()
            f = lambda v: float(v) if v not in ("[N/A]", "N/A", "") else None
            out.append((t, f(c[1]), f(c[2]), f(c[3]), f(c[4]), int(c[5], 16), c[6]))
        except ValueError:
            continue
    return out


def span(vals):
    vals = [v for v in vals if v is not None]
    if not vals:
        return "-"
    lo, hi = min(vals), max(vals)
    return f"{lo:.0f}" if lo == hi else f"{lo:.0f}-{hi:.0f}"


def state(path, spans_path, out):
    import os
    spans = []
    for line in open(spans_path):
        parts = line.strip().split("|")
        if len(parts) == 3:
            spans.append((parts[0], float(parts[1]), float(parts[2])))
    if path == "none":
        text = ("Device state: not recorded (nvidia-smi not found; the clocks, power and "
                "throttle reasons of this device are unknown).")
        print(text + "\n")
        lines = {name: text for name, _, _ in spans}
    else:
        rows = samples(path)
        print("Device state per step (nvidia-smi every 200 ms, read-only):\n")
        print("| step | samples | SM MHz | memory MHz | power W | temperature C | throttle reasons |")
        print("|---|---|---|---|---|---|---|")
        lines = {}
        for name, a, b in spans:
            mine = [r for r in rows if a <= r[0] <= b]
            bits = 0
            for r in mine:
                bits |= r[5]
            why = ", ".join(v for k, v in REASONS.items() if bits & k) or "none"
            cells = [span([r[1] for r in mine]), span([r[2] for r in mine]),
                     span([r[3] for r in mine]), span([r[4] for r in mine])]
            print(f"| {name} | {len(mine)} | " + " | ".join(cells) + f" | {why} |")
            lines[name] = (f"Device state during these rows ({len(mine)} nvidia-smi samples): SM "
                           f"{cells[0]} MHz, memory {cells[1]} MHz, power {cells[2]} W, "
                           f"{cells[3]} C, throttle reasons: {why}.")
        print()
    for name, text in lines.items():
        page = page_of(name)
        p = page and os.path.join(out, page)
        if p and os.path.exists(p):
            with open(p, "a") as f:
                f.write(f"\n{text}\n")


if __name__ == "__main__":
    what, path, command = sys.argv[1:4]
    if what == "state":
        state(path, command, sys.argv[4])
        sys.exit(0)
    {"character": character, "dambreak": dambreak}[what](path, command)
