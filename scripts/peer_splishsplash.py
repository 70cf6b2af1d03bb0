"""SPlisHSPlasH's DFSPH (pysplishsplash) on fluidform's dam break: run by
scripts/peer_splishsplash.sh inside its virtual environment.

Usage: python peer_splishsplash.py OUT_JSON SPACING SECONDS ERROR_PCT

The tank (2.4 x 1.4 x 0.8 m, volume-map walls) and the column (0.8 x 1.0 x 0.8 m at the
origin) of fluidform's dam-break scene, particles of diameter SPACING, DFSPH iterating to
a mean density error of ERROR_PCT percent (both solves), its own CFL step (factor 1, at
most 5 ms, its dam-break scene's). Writes the particle count, the simulated and wall
seconds from the end of the first step to the last (set-up and the volume map left out,
the density sampling taken out), steps, and the mean over
sampled steps of the mean over particles of max(rho / rho0 - 1, 0), fluidform's measure.
"""
import json
import os
import sys
import tempfile
import time

import pysplishsplash as sph


def scene(spacing, seconds, error):
    return {
        "Configuration": {
            "particleRadius": spacing / 2,
            "numberOfStepsPerRenderUpdate": 1,
            "simulationMethod": 4,
            "gravitation": [0, -9.81, 0],
            "timeStepSize": 0.001,
            "cflMethod": 1,
            "cflFactor": 1,
            "cflMaxTimeStepSize": 0.005,
            "boundaryHandlingMethod": 2,
            "stopAt": seconds,
            "enableVTKExport": False,
            "enablePartioExport": False,
            "DFSPH": {
                "minIterations": 2,
                "maxIterations": 100,
                "maxError": error,
                "maxIterationsV": 100,
                "maxErrorV": error,
                "enableDivergenceSolver": True,
            },
        },
        "Materials": [
            {
                "id": "Fluid",
                "density0": 1000,
                "viscosityMethod": 1,
                "Standard viscosity": {"viscosity": 0.01},
            }
        ],
        "RigidBodies": [
            {
                "geometryFile": os.path.join(models(), "UnitBox.obj"),
                "translation": [1.2, 0.7, 0.4],
                "scale": [2.4, 1.4, 0.8],
                "isDynamic": False,
                "isWall": True,
                "mapInvert": True,
                "mapThickness": 0.0,
                "mapResolution": [48, 28, 16],
            }
        ],
        "FluidBlocks": [
            {"denseMode": 0, "start": [0.0, 0.0, 0.0], "end": [0.8, 1.0, 0.8]}
        ],
    }


def models():
    """The package's bundled models (UnitBox.obj), beside its data/Scenes."""
    for root, _, files in os.walk(sys.prefix):
        if "UnitBox.obj" in files:
            return root
    sys.exit("pysplishsplash's UnitBox.obj not found under " + sys.prefix)


def main():
    out, spacing, seconds, error = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
    work = tempfile.mkdtemp(prefix="peer-sph-")
    path = os.path.join(work, "dam.json")
    with open(path, "w") as f:
        json.dump(scene(spacing, seconds, error), f)
    base = sph.Exec.SimulatorBase()
    base.init(
        sceneFile=path,
        programName="peer",
        useCache=False,
        outputDir=work,
        initialPause=False,
        useGui=False,
        stopAt=seconds,
    )
    # Per step (after the first, whose end starts the clock): the wall time, the
    # simulated time; every fifth step the density error, its time set aside.
    state = {"steps": 0, "sampling": 0.0, "errors": [], "first": None, "last": None, "n": 0}

    def after_step():
        now = time.perf_counter() - state["sampling"]
        t = sph.TimeManager.getCurrent().getTime()
        fluid = sph.Simulation.getCurrent().getFluidModel(0)
        state["n"] = fluid.numActiveParticles()
        if state["first"] is None:
            state["first"] = (now, t)
            return
        state["steps"] += 1
        state["last"] = (now, t)
        if state["steps"] % 5:
            return
        t0 = time.perf_counter()
        n, rho0 = state["n"], fluid.getDensity0()
        e = sum(max(fluid.getDensity(i) / rho0 - 1.0, 0.0) for i in range(n)) / n
        state["errors"].append(e)
        state["sampling"] += time.perf_counter() - t0

    base.setTimeStepCB(after_step)
    base.run()  # cleans the simulation up when it stops
    (w0, t0), (w1, t1) = state["first"], state["last"]
    steps, errors = state["steps"], state["errors"]
    result = {
        "particles": state["n"],
        "spacing": spacing,
        "simulated_s": t1 - t0,
        "wall_s": w1 - w0,
        "sim_s_per_wall_s": (t1 - t0) / (w1 - w0),
        "steps": steps,
        "ms_per_step": 1000.0 * (w1 - w0) / steps,
        "mean_dt_ms": 1000.0 * (t1 - t0) / steps,
        "mean_density_error": sum(errors) / max(len(errors), 1),
        "threads": os.environ.get("OMP_NUM_THREADS", "all"),
        "version": "pysplishsplash 2.19.0",
    }
    with open(out, "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
