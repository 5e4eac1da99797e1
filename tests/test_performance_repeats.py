"""The speed-against-error study times every (variant, level) REPEATS (seven) times, long runs
too: the median and the spread of every point rest on as many runs."""

from pathlib import Path

import pytest

from experiments.performance import front

CANTILEVER = Path(front.__file__).resolve().parent / "scenes" / "cantilever.yaml"


class _Stop(Exception):
    pass


def test_the_study_asks_the_engine_for_seven_runs_of_every_point(monkeypatch):
    import msslib.planning

    seen = {}

    def engine(scene, **kw):
        seen.update(kw)
        raise _Stop

    monkeypatch.setattr(msslib.planning, "measure_front", engine)
    with pytest.raises(_Stop):
        front.measure(CANTILEVER, [0, 1], front.REPEATS)
    assert front.REPEATS >= 7 and seen["repeats"] == front.REPEATS
    assert seen["long_run"] is None  # no run is timed once for being long


def test_a_long_run_is_timed_as_often_as_a_short_one(monkeypatch):
    """The engine's timing loop with ``long_run=None`` runs every repeat of a run that takes 60 s
    of CPU time (a clock that advances 60 s per run); with ``long_run=5`` it stopped after one."""
    import time

    import msslib.planning
    from msslib.planning import front as engine

    clock = {"t": 0.0}

    class Ds:
        attrs = {"wall_time_s": 60.0}

    def run(scene, budget, cpu):
        clock["t"] += 60.0
        return Ds()

    monkeypatch.setattr(msslib.planning, "run_with_budget", run)
    monkeypatch.setattr(time, "process_time", lambda: clock["t"])
    monkeypatch.setattr("msslib.scene.load_scene", lambda raw, base_dir=None: raw)
    spread = []
    t, wall, runs, _ = engine._timed({}, None, 7, None, True, None, spread)
    assert (t, wall, runs) == (60.0, 60.0, 7) and spread == [60.0, 60.0, 60.0]
    _, _, runs_long, _ = engine._timed({}, None, 7, None, True, 5.0, [])
    assert runs_long == 1
