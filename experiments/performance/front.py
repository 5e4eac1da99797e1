"""Shared body of the speed-against-error studies: measure a scene's front, write it atomically."""

import argparse
import os
from pathlib import Path

from msslib.io import write_result
from msslib.planning import measure_front

HERE = Path(__file__).resolve().parent


def main(scene: str, levels, quick_levels=(1,)):
    p = argparse.ArgumentParser(description=f"speed against error for {scene}")
    p.add_argument("--out", required=True)
    p.add_argument("--quick", action="store_true")
    a = p.parse_args()
    front = measure_front(HERE / "scenes" / scene, levels=quick_levels if a.quick else levels,
                          repeats=1 if a.quick else 3, budget=60.0, progress=lambda s: print(s, flush=True))
    front.attrs["scene_file"] = f"experiments/performance/scenes/{scene}"
    front.attrs["threads"] = os.environ.get("OMP_NUM_THREADS", "default")
    write_result(a.out, front)
