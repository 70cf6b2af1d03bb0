#!/usr/bin/env python3
"""Markdown pages of scripts/gpu.sh's own parts, from the files fluidform writes.

  gpu_report.py character SUMMARY_JSON COMMAND   -> the liquid character's page
  gpu_report.py dambreak STABILITY_JSON COMMAND  -> the 1M DFSPH dam break's page
Prints the page on stdout.
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


if __name__ == "__main__":
    what, path, command = sys.argv[1:4]
    {"character": character, "dambreak": dambreak}[what](path, command)
