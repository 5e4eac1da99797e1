"""The abstract and the introduction say on which meshes the FEM references are computed: on the
MSS's own mesh for Lloyd's and Golec's experiments (Lloyd's resolution study: on its finest mesh),
on finer meshes for Baudet's beams and L-block (the cantilever also on the MSS's own meshes). These
tests read the experiment files, so a change of mesh contradicts the sentence and fails here."""

from pathlib import Path

import pytest

from msslib.experiment import load_experiment, scene_of

ROOT = Path(__file__).resolve().parents[1]
EXP = ROOT / "experiments"
SAME_MESH = sorted(p for d in ("lloyd", "golec") for p in (EXP / d).glob("*.yaml") if p.stem != "resolutions")
FINER_MESH = [EXP / "baudet" / f"{n}.yaml" for n in ("cantilever", "shear_beam", "l_block")]


def _geometry(exp, case, model):
    return scene_of(exp, case, model)["geometry"]


def test_the_sentence_covers_experiments():
    assert len(SAME_MESH) >= 10 and all(p.is_file() for p in FINER_MESH)


@pytest.mark.parametrize("path", SAME_MESH, ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_lloyd_and_golec_references_on_the_models_own_mesh(path):
    exp = load_experiment(path)
    assert exp.reference is not None
    for case in exp.cases:
        ref = _geometry(exp, case, exp.reference)
        for model in exp.models:
            assert _geometry(exp, case, model) == ref, f"{exp.name}/{case}/{model}: not the reference's mesh"


def test_lloyd_resolutions_reference_on_the_finest_mesh():
    exp = load_experiment(EXP / "lloyd" / "resolutions.yaml")
    case = next(iter(exp.cases))
    ref = _geometry(exp, case, exp.reference)
    sizes = {m: _geometry(exp, case, m)["args"]["nx"] for m in exp.models}
    assert ref["args"]["nx"] == max(sizes.values())
    assert min(sizes.values()) < ref["args"]["nx"]


@pytest.mark.parametrize("path", FINER_MESH, ids=lambda p: p.stem)
def test_baudet_references_on_finer_meshes(path):
    exp = load_experiment(path)
    case = next(iter(exp.cases))
    ref_geom = _geometry(exp, case, exp.reference)
    ref_args = ref_geom["args"]
    for model in exp.models:
        if not model.startswith("mss"):
            continue
        args = _geometry(exp, case, model)["args"]
        for key in ("nx", "ny", "nz", "n"):
            if key in ref_args:
                assert ref_args[key] > args[key], f"{exp.name}/{model}: reference not finer along {key}"


def test_baudet_cantilever_also_has_fem_on_each_mss_mesh():
    exp = load_experiment(EXP / "baudet" / "cantilever.yaml")
    case = next(iter(exp.cases))
    fem_meshes = [_geometry(exp, case, m) for m in exp.models if m.startswith("fem_")]
    for model in ("mss_4x1x1", "mss_8x2x2", "mss_16x4x4"):
        assert _geometry(exp, case, model) in fem_meshes, model
