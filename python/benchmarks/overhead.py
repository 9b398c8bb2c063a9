"""What the Python call costs beyond the render itself, against `fourfold render`, and the
time to import the package (docs/benchmarks.md, "Python").

    python python/benchmarks/overhead.py [RUNS]    # after pip install ./python, cargo build --release

For each scene at 512 × 512: the median wall time of `fourfold render` (a process: start,
GPU, tree, shader, pipeline, frame, PNG written) and of `fourfold.render` in a process that
has drawn once (its GPU open), each with the stages it reports (tree, codegen, pipeline,
frame); "beyond" is wall − stages, the cost of the call around the render.
"""

import os
import pathlib
import re
import statistics
import subprocess
import sys
import tempfile
import time

import fourfold

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLI = os.environ.get("FOURFOLD_CLI", str(ROOT / "target" / "release" / "fourfold"))
SCENES = [
    ("glome", "x^2 + y^2 + z^2 + w^2 = 1", {}),
    ("fig-3-9-left", str(ROOT / "examples" / "scenes" / "fig-3-9-left.toml"), {}),
    ("spheritorus", str(ROOT / "examples" / "scenes" / "spheritorus.toml"), {}),
]


def cli_once(scene: str, out: str) -> tuple[float, float]:
    started = time.perf_counter()
    done = subprocess.run([CLI, "render", scene, "-o", out, "--size", "512x512"], capture_output=True, text=True, check=True)
    wall = time.perf_counter() - started
    times = re.search(r"tree ([\d.]+), codegen\+validate ([\d.]+), pipeline ([\d.]+), frame ([\d.]+)", done.stdout)
    return wall * 1e3, sum(float(t) for t in times.groups())


def python_once(scene: str) -> tuple[float, float]:
    started = time.perf_counter()
    picture = fourfold.render(scene, size=(512, 512))
    wall = time.perf_counter() - started
    t = picture.info["times_ms"]
    return wall * 1e3, t["tree"] + t["codegen"] + t["pipeline"] + t["frame"]


def median(pairs):
    return statistics.median(p[0] for p in pairs), statistics.median(p[1] for p in pairs)


def main(runs: int = 5) -> None:
    fourfold.render("x = 0", size=(8, 8))  # opens the GPU once, as a notebook has
    print(f"{'scene':<14} {'CLI wall':>9} {'stages':>8} {'beyond':>7}   {'Python wall':>11} {'stages':>8} {'beyond':>7} {'(%)':>6}")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "p.png")
        for name, scene, _ in SCENES:
            cli = median([cli_once(scene, out) for _ in range(runs)])
            py = median([python_once(scene) for _ in range(runs)])
            beyond = py[0] - py[1]
            print(
                f"{name:<14} {cli[0]:>7.0f}ms {cli[1]:>6.0f}ms {cli[0] - cli[1]:>5.0f}ms   "
                f"{py[0]:>9.0f}ms {py[1]:>6.0f}ms {beyond:>5.0f}ms {100 * beyond / py[1]:>5.1f}%"
            )

    def timed(code: str) -> float:
        started = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True)
        return (time.perf_counter() - started) * 1e3
    bare = statistics.median(timed("pass") for _ in range(runs))
    numpy = statistics.median(timed("import numpy") for _ in range(runs))
    ours = statistics.median(timed("import fourfold") for _ in range(runs))
    print(f"import: python alone {bare:.0f} ms, import numpy {numpy:.0f} ms, import fourfold {ours:.0f} ms "
          f"({ours - numpy:.0f} ms beyond numpy)")


if __name__ == "__main__":
    main(*map(int, sys.argv[1:2]))
