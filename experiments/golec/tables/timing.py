"""Wall time of a 10 s simulation of 1,000 Golec cubes beside the paper's 2.88 s."""

import argparse

from msslib.io import read_result, write_text

INPUTS = ["results/golec/studies/timing.nc"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    d = read_result(INPUTS[0])
    v = {k: float(d[k]) for k in d.data_vars}
    quick = " (quick build: simulated time shortened, wall time scaled to 10 s)" if int(d.attrs.get("quick", 0)) else ""
    lines = [f"**Timing: 10 s of simulated time, 10 x 10 x 10 Golec cubes (1,000 elements, {int(v['n_nodes'])} nodes).**{quick}", "",
             "| run | material | integrator, time step | simulated (s) | wall time (s) | wall time for 10 s (s) | cores |",
             "|---|---|---|---|---|---|---|",
             f"| Golec et al. (published) | not given | not given | 10 | 2.88 | 2.88 | {int(v['published_cores'])} |",
             f"| ours, gravity, bottom fixed | E = 400 kPa, nu = 0.3 | velocity Verlet, dt = {v['dt'] * 1e3:.3g} ms "
             f"({int(v['n_steps'])} steps) | {v['simulated_time']:g} | {v['wall_time']:.3g} | {v['wall_time_10s']:.3g} | 1 |",
             f"| ours, same, extrapolated | E = 20 kPa, nu = 0.4999 | velocity Verlet, dt = {v['incompressible_dt'] * 1e3:.3g} ms | "
             f"{v['incompressible_simulated_time']:g} | {v['incompressible_wall_time']:.3g} | "
             f"{v['incompressible_wall_time_10s_extrapolated']:.3g} (extrapolated) | 1 |"]
    write_text(args.out, "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
