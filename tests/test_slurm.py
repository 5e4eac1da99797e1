"""The workflow on a SLURM cluster, through the tested profile (profiles/slurm) and Snakemake's SLURM
executor plugin: a one-node cluster on this machine (profiles/slurm/cluster.sh) runs a named subset of
the quick build as batch jobs, and its results equal those of a local run of the same copy.

The subset: one experiment (lloyd/membrane_square: six runs, its comparison and comparison table), a
figure drawn from those runs, and a study with a table drawn from it (lloyd/load_sweep). Both runs
start from the same copy of the repository in which every file has one modification time (as in a
fresh clone), so that the committed derivation results count as up to date (the derivations are
checked by `python -m derivations.codegen --check`). Where the cluster cannot be started (not root,
no packages and no apt-get, a daemon that does not come up), the test fails with cluster.sh's one
line. About a minute and a half on two cores.
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from system_packages import install_lock

ROOT = Path(__file__).resolve().parents[1]
PROFILE = Path("profiles", "slurm")
CLUSTER = ROOT / PROFILE / "cluster.sh"

TARGETS = [
    "results/lloyd/membrane_square/comparison.nc",
    "paper/tables/experiments/lloyd_membrane_square.md",
    "paper/figures/lloyd_membrane_square.png",
    "paper/tables/lloyd_load_sweep.md",
]
# the rules these targets need, one job each (the figure, declared in the experiment file, reads the runs;
# the table the study)
JOBS = {"experiment_lloyd_membrane_square", "experiment_compare", "experiment_figure", "study", "table"}
# for this machine's small cluster: job states from squeue (no accounting database; the cluster keeps
# finished jobs for an hour), the first status check after a second, and the jobs' logs kept
CLUSTER_OPTIONS = ["--slurm-status-command", "squeue", "--slurm-init-seconds-before-status-checks", "1",
                   "--slurm-keep-successful-logs"]
# what differs between two runs of the same inputs: when and where they ran, and how long they took
PROVENANCE = {"history", "created", "git_commit", "msslib_version", "python_version", "numpy_version"}


def is_timing(name):
    return name.endswith(("wall_time", "wall_time_s", "_solve_time", "_assembly_time"))


def copy_repository(dest):
    """The repository's files (tracked, and new ones git does not ignore) copied to ``dest``, all
    with one modification time."""
    listed = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                            cwd=ROOT, capture_output=True, text=True, check=True).stdout
    stamp = time.time() - 60
    for rel in filter(None, listed.split("\0")):
        src = ROOT / rel
        if src.is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, dest / rel)
            shutil.copymode(src, dest / rel)
            os.utime(dest / rel, (stamp, stamp))
    return dest


def snakemake(*args, cwd, env=None, timeout=420):
    return subprocess.run([sys.executable, "-m", "snakemake", *args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=timeout)


def tail(text, n=25):
    return "\n".join(text.splitlines()[-n:])


@pytest.fixture
def cluster():
    """A one-node cluster for this test alone: its own folder (a short path, for munge's socket),
    munge key and ports. Yields (folder, environment for its clients)."""
    folder = Path(tempfile.mkdtemp(prefix="msslib-slurm-"))
    with install_lock():  # up may install slurm and munge: not while another test installs
        up = subprocess.run(["bash", str(CLUSTER), "up", str(folder)], capture_output=True, text=True, timeout=900)
    if up.returncode != 0:
        shutil.rmtree(folder, ignore_errors=True)
        lines = (up.stderr or up.stdout).strip().splitlines()
        pytest.fail(lines[-1] if lines else f"cluster.sh up exited with {up.returncode}", pytrace=False)
    env = dict(os.environ, SLURM_CONF=str(folder / "slurm.conf"), PATH=f"{folder / 'bin'}{os.pathsep}{os.environ['PATH']}")
    try:
        yield folder, env
    finally:
        subprocess.run(["bash", str(CLUSTER), "down", str(folder)], capture_output=True, timeout=120)
        shutil.rmtree(folder, ignore_errors=True)


def assert_same_dataset(path_a, path_b):
    """Every variable (data and coordinates) bitwise equal as stored (dtype, shape, bytes; no
    decoding), with equal attributes; global attributes equal apart from provenance and timings."""
    a, b = xr.load_dataset(path_a, decode_cf=False), xr.load_dataset(path_b, decode_cf=False)
    assert set(a.variables) == set(b.variables), path_a
    compared = 0
    for name in a.variables:
        assert str(a[name].attrs) == str(b[name].attrs), (path_a, name)
        if is_timing(name):
            continue
        u, v = a[name].values, b[name].values
        assert (u.dtype, u.shape, a[name].dims) == (v.dtype, v.shape, b[name].dims), (path_a, name)
        if u.dtype.kind in "OUS":
            assert u.tolist() == v.tolist(), (path_a, name)
        else:
            assert u.tobytes() == v.tobytes(), f"{path_a}: {name} differs (max |diff| {np.max(np.abs(u - v))})"
        compared += 1
    assert compared > 0, path_a
    keys = {k for k in set(a.attrs) | set(b.attrs) if k not in PROVENANCE and not is_timing(k)}
    assert {k: str(a.attrs.get(k)) for k in keys} == {k: str(b.attrs.get(k)) for k in keys}, path_a


def table_without_timings(path):
    """The table's lines with the cells of its wall-time columns blanked."""
    lines = Path(path).read_text().splitlines()
    header = next(line for line in lines if line.startswith("| "))
    timed = [i for i, cell in enumerate(header.split("|")) if "time" in cell]
    return ["|".join("" if i in timed else c for i, c in enumerate(line.split("|"))) if line.startswith("|") else line
            for line in lines]


def test_subset_through_slurm_equals_local_run(cluster, tmp_path):
    folder, env = cluster
    local = copy_repository(tmp_path / "local")
    remote = tmp_path / "slurm"
    shutil.copytree(local, remote)  # the same files, the same times
    submitted = subprocess.Popen([sys.executable, "-m", "snakemake", "--profile", str(PROFILE), *CLUSTER_OPTIONS,
                                  *TARGETS, "--config", "quick=1"], cwd=remote, env=env, stdout=subprocess.PIPE,
                                 stderr=subprocess.STDOUT, text=True)
    try:
        here = snakemake("--cores", "2", *TARGETS, "--config", "quick=1", cwd=local)
        out, _ = submitted.communicate(timeout=480)
    finally:
        if submitted.poll() is None:
            submitted.kill()
    assert here.returncode == 0, tail(here.stderr)
    assert submitted.returncode == 0, tail(out) + "\n" + tail((folder / "slurmctld.log").read_text(), 10)

    # the executor submitted one SLURM job per rule of the subset, and the scheduler ran each to completion
    run_id = re.search(r"SLURM run ID: (\S+)", out).group(1)
    submissions = dict(re.findall(r"Job \d+ has been submitted with SLURM jobid (\d+) \(log: (\S+?)\)\.?$", out, re.M))
    done = re.search(r"(\d+) of (\d+) steps \(100%\) done", here.stdout + here.stderr)
    assert done and int(done.group(1)) == len(JOBS), tail(here.stderr)
    assert len(submissions) == len(JOBS), out
    rules = {Path(log).relative_to(remote / ".snakemake" / "slurm_logs").parts[0] for log in submissions.values()}
    assert rules == {f"rule_{name}" for name in JOBS}
    for jobid, log in submissions.items():
        assert "Finished jobid" in Path(log).read_text(), log  # the job's own Snakemake, on the node
    completed = [dict(re.findall(r"(\w+)=(\S*)", line)) for line in (folder / "jobcomp.log").read_text().splitlines()]
    ours = {r["JobId"]: r for r in completed if r["Name"] == run_id}
    assert set(ours) == set(submissions)
    defaults = yaml.safe_load((ROOT / PROFILE / "config.yaml").read_text())["default-resources"]
    for record in ours.values():
        assert record["JobState"] == "COMPLETED" and record["ExitCode"] == "0:0", record
        # the profile's defaults reached the scheduler: one core, its memory, its time limit (minutes)
        assert record["Tres"].startswith(f"cpu=1,mem={defaults['mem_mb']}M,"), record
        assert record["TimeLimit"] == str(defaults["runtime"]), record
    controller = (folder / "slurmctld.log").read_text()
    for jobid in submissions:
        assert f"_job_complete: JobId={jobid} WEXITSTATUS 0" in controller, jobid

    # the same results as the local run
    results = sorted(p.relative_to(local) for p in (local / "results").rglob("*.nc"))
    assert len(results) == 8  # six runs, the comparison, the study
    assert results == sorted(p.relative_to(remote) for p in (remote / "results").rglob("*.nc"))
    for rel in results:
        assert_same_dataset(local / rel, remote / rel)
    for table in ("paper/tables/experiments/lloyd_membrane_square.md", "paper/tables/lloyd_load_sweep.md"):
        assert table_without_timings(remote / table) == table_without_timings(local / table), table
    figure = (remote / "paper/figures/lloyd_membrane_square.png").read_bytes()
    assert figure.startswith(b"\x89PNG") and len(figure) > 10_000


def test_rules_ask_the_scheduler_for_what_they_need(tmp_path):
    """A study whose rule declares nothing gets the profile's defaults; the dense Baudet cantilever
    study asks for more memory in a full build (not in a quick one); the benchmarks ask for a node of
    their own."""
    repo = copy_repository(tmp_path / "repo")
    targets = ["results/baudet/studies/cantilever_floor.nc", "results/lloyd/studies/load_sweep.nc",
               "results/benchmarks.json"]
    defaults = yaml.safe_load((ROOT / PROFILE / "config.yaml").read_text())["default-resources"]

    def resources(*config):
        dry = snakemake("-n", "--profile", str(PROFILE), *targets, *config, cwd=repo, timeout=300)
        assert dry.returncode == 0, tail(dry.stdout + dry.stderr)
        jobs, text = {}, dry.stdout + dry.stderr
        for block in re.split(r"\n(?=rule \w+:)", text):
            out = re.search(r"output: (\S+)", block)
            res = re.search(r"resources: (.*)", block)
            if out and res and out.group(1) in targets:
                jobs[out.group(1)] = dict(item.split("=", 1) for item in res.group(1).split(", "))
        assert set(jobs) == set(targets), text[-3000:]
        return jobs

    full, quick = resources(), resources("--config", "quick=1")
    light = full["results/lloyd/studies/load_sweep.nc"]
    assert (light["mem_mb"], light["runtime"]) == (str(defaults["mem_mb"]), str(defaults["runtime"]))
    dense = full["results/baudet/studies/cantilever_floor.nc"]
    assert int(dense["mem_mb"]) >= 3700 > defaults["mem_mb"]  # its measured peak: 3.7 GB
    assert quick["results/baudet/studies/cantilever_floor.nc"]["mem_mb"] == str(defaults["mem_mb"])
    assert full["results/benchmarks.json"]["slurm_extra"] == "--exclusive"


def test_readme_shows_the_tested_profile():
    """The README's cluster section shows the profile this test runs, setting for setting."""
    section = (ROOT / "README.md").read_text().split("### On a cluster", 1)[1].split("\n## ", 1)[0]
    shown = re.findall(r"```yaml\n(.*?)```", section, re.S)
    assert len(shown) == 1
    assert yaml.safe_load(shown[0]) == yaml.safe_load((ROOT / PROFILE / "config.yaml").read_text())
