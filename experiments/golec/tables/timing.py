"""Wall time of a 10 s simulation of 1,000 Golec cubes beside the paper's 2.88 s on 8 cores."""

from experiments import script
from msslib.results import read_result

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def main():
    args = script.args(__doc__)
    d = read_result(INPUTS[0])
    v = {k: float(d[k]) for k in d.data_vars}
    quick = " (quick build: simulated time shortened, wall time scaled to 10 s)" if int(d.attrs.get("quick", 0)) else ""
    cores = int(v["published_cores"])
    extrapolated = " (extrapolated)" if v["comparable_simulated_time"] < 9.999 else ""
    lines = [f"**Timing: 10 s of simulated time, 10 x 10 x 10 Golec cubes (1,000 elements, {int(v['n_nodes'])} nodes).**{quick}", "",
             "| run | material | integrator, time step | simulated (s) | steps | wall time (s) | wall time for 10 s (s) | cores "
             "| core-seconds for 10 s (time x cores) | wall time per cube and step (µs) |",
             "|---|---|---|---|---|---|---|---|---|---|",
             f"| Golec et al. (published) | not stated for the timing (their compression sample: E = 20 kPa, nu = 0.4999) "
             f"| not given | 10 | not given | 2.88 | 2.88 | {cores} | at most {v['published_core_seconds']:.3g} | unknown (steps not given) |",
             f"| ours, comparable: paper's material, structured-lattice kernels | E = 20 kPa, nu = 0.4999 "
             f"| symplectic Euler, dt = {v['comparable_dt'] * 1e6:.3g} µs ({v['comparable_dt'] / v['comparable_dt_critical']:.2f} x the "
             f"critical {v['comparable_dt_critical'] * 1e6:.3g} µs) | {v['comparable_simulated_time']:.3g} | {int(v['comparable_n_steps'])} "
             f"| {v['comparable_wall_time']:.3g} (CPU {v['comparable_cpu_time']:.3g}) "
             f"| {v['comparable_wall_time_10s']:.3g} (CPU {v['comparable_cpu_time_10s']:.3g}){extrapolated} | 1 "
             f"| {v['comparable_cpu_time_10s']:.3g} (CPU) | {v['comparable_time_per_cube_step'] * 1e6:.3g} "
             f"(CPU {v['comparable_cpu_time_per_cube_step'] * 1e6:.3g}) |",
             f"| ours, generic kernels, gravity | E = 400 kPa, nu = 0.3 | velocity Verlet, dt = {v['dt'] * 1e6:.3g} µs "
             f"| {v['simulated_time']:g} | {int(v['n_steps'])} | {v['wall_time']:.3g} | {v['wall_time_10s']:.3g} | 1 "
             f"| {v['wall_time_10s']:.3g} | {v['wall_time_per_step'] / v['n_elements'] * 1e6:.3g} |",
             f"| ours, generic kernels, same load | E = 20 kPa, nu = 0.4999 | velocity Verlet, dt = {v['incompressible_dt'] * 1e6:.3g} µs "
             f"| {v['incompressible_simulated_time']:g} | {int(round(v['incompressible_simulated_time'] / v['incompressible_dt']))} "
             f"| {v['incompressible_wall_time']:.3g} | {v['incompressible_wall_time_10s_extrapolated']:.3g} (extrapolated) | 1 "
             f"| {v['incompressible_wall_time_10s_extrapolated']:.3g} "
             f"| {v['incompressible_wall_time'] / round(v['incompressible_simulated_time'] / v['incompressible_dt']) / v['n_elements'] * 1e6:.3g} |",
             "",
             f"All runs: 1 cm cubes, bottom face clamped, released from rest under gravity, mass-proportional damping 5 1/s, one "
             f"thread, on a shared {int(v['machine_cores'])}-core host (wall time; CPU time where stated). The paper gives no time "
             f"step: at our CPU cost per cube and step, one core would spend the paper's 2.88 s with a step of "
             f"{v['break_even_dt_wall'] * 1e6:.3g} µs, and {cores} fully used cores ({v['published_core_seconds']:.3g} core-seconds) "
             f"with a step of {v['break_even_dt_core'] * 1e6:.3g} µs; the explicit stability limit of this lattice is "
             f"{v['comparable_dt_critical'] * 1e6:.3g} µs."]
    script.write_table(args.out, lines)


if __name__ == "__main__":
    main()
