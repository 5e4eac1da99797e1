# msslib workflow. One direction: derivations -> generated code -> runs (NetCDF) -> figures and
# tables -> paper. Every rule calls one entry point of derivations/ or msslib, or one script of
# experiments/; there is no physics here.
#
#   snakemake -j2                    everything
#   snakemake -j2 --config quick=1   a reduced version of every output (CI)
#   snakemake -n                     the whole DAG
#   snakemake --report report.html   a report of the figures, tables and paper (after a build)
#
# Layout the rules discover (add a file, the DAG grows):
#   experiments/<paper>/<name>.yaml              an experiment: cases x model variants (msslib.experiment),
#                                                and the figures drawn from its runs (its figures block)
#   experiments/<paper>/studies/<study>.py       a sweep script writing one NetCDF
#   experiments/<paper>/figures/curves.yaml      figures that draw a study result as error curves (data)
#   experiments/<paper>/figures/<fig>.py         a figure that computes or draws something of its own
#   experiments/<paper>/tables/<table>.py        one table
#   experiments/<paper>/{figures,tables}/inputs.yaml   the results each of those scripts reads
# Every study, figure and table takes one command line: --out PATH (a study's NetCDF file, a figure's
# stem: STEM.png and STEM.pdf, a table's Markdown file) and --quick (figures and tables accept it).

import hashlib
import json
import re
from pathlib import Path

import yaml

from msslib.experiment import figure_runs, load_experiment

QUICK = bool(int(config.get("quick", 0)))
QFLAG = "--quick" if QUICK else ""
PAPERS = ["lloyd", "baudet", "golec", "performance", "summary"]
# the modules codegen derives (derivations/elements/, derivations/terms/; derivations.registry finds
# them the same way), name -> source file, and the engine: every file directly in derivations/
DERIVATIONS = {p.stem: str(p) for kind in ("elements", "terms")
               for p in sorted(Path("derivations", kind).glob("*.py")) if not p.stem.startswith("_")}
# analyses generate no code; codegen writes their results into paper/derivations.* too
ANALYSES = sorted(str(p) for p in Path("derivations", "analyses").glob("*.py") if not p.stem.startswith("_"))
ENGINE = sorted(str(p) for p in Path("derivations").glob("*.py"))
# the derivation modules as notebooks: one HTML page each, beside the paper (linked as derivations/<name>.html).
# Each page re-runs its derivation (seconds to a minute of SymPy), so the quick build renders one of
# them, the first, as its reduced version of the set; the full build renders every page.
NOTEBOOKS = [f"paper/build/derivations/{m}.html" for m in (list(DERIVATIONS)[:1] if QUICK else DERIVATIONS)]
SCENES = sorted(glob_wildcards("experiments/scenes/{name}.yaml").name)
# every result depends on the library that computed it: a change in msslib reruns what it touches
# (the paper builder and the plotting, experiments/paper.py and experiments/plotting.py, compute no
# result: only the paper and the figure rules depend on them)
MSSLIB = sorted(str(p) for p in Path("msslib").rglob("*.py"))

wildcard_constraints:
    paper="|".join(PAPERS),
    exp=r"[A-Za-z0-9_\-]+",
    case=r"[A-Za-z0-9_\-]+?",
    model=r"[A-Za-z0-9_\-]+",
    name=r"[A-Za-z0-9_\-]+",


def experiments():
    return {(p.parent.name, p.stem): p for paper in PAPERS for p in sorted(Path("experiments", paper).glob("*.yaml"))}


def runs(paper, exp):
    raw = yaml.safe_load(Path("experiments", paper, f"{exp}.yaml").read_text())
    cases = raw.get("cases") or {"default": {}}
    return [f"{c}__{m}" for c in cases for m in raw["models"]]


def scripts(kind):
    return {(p.parent.parent.name, p.stem): p for paper in PAPERS for p in sorted(Path("experiments", paper, kind).glob("*.py"))}


def declared_inputs(paper, kind, name):
    """The results a figure or table script reads, from the inputs.yaml beside it (data: no script runs)."""
    path = Path("experiments", paper, kind, "inputs.yaml")
    declared = (yaml.safe_load(path.read_text()) or {}) if path.is_file() else {}
    if name not in declared:
        raise ValueError(f"{path}: {name} is not declared (list the results {kind}/{name}.py reads)")
    return list(declared[name])


def declared_figures():
    """The figures declared in the experiment files (their figures block): (paper, name) -> (experiment
    name, the experiment loaded and checked)."""
    out = {}
    for (paper, exp), path in experiments().items():
        loaded = load_experiment(path)
        for name in loaded.figures:
            if (paper, name) in out or (paper, name) in scripts("figures"):
                raise ValueError(f"{path}: figure {name!r} of {paper} is declared twice")
            out[(paper, name)] = (exp, loaded)
    return out


EXPERIMENT_FIGURES = declared_figures()


def curve_figures():
    """The figures declared in experiments/<paper>/figures/curves.yaml (study results drawn as error
    curves): (paper, name) -> the study result each reads."""
    from experiments.figures import load_curves

    out = {}
    for paper in PAPERS:
        path = Path("experiments", paper, "figures", "curves.yaml")
        if path.is_file():
            for name, spec in load_curves(path).items():
                if (paper, name) in EXPERIMENT_FIGURES or (paper, name) in scripts("figures"):
                    raise ValueError(f"{path}: figure {name!r} of {paper} is declared twice")
                out[(paper, name)] = spec["result"]
    return out


CURVE_FIGURES = curve_figures()


# `snakemake --report`: figures, tables and the paper, one category per paper (captions in paper/report/)
report: "paper/report/workflow.rst"

COMPARISONS = [f"results/{p}/{n}/comparison.nc" for p, n in experiments()]
STUDIES = [f"results/{p}/studies/{n}.nc" for p, n in scripts("studies")]
FIGURES = sorted(f"paper/figures/{p}_{n}.png"
                 for p, n in list(scripts("figures")) + list(EXPERIMENT_FIGURES) + list(CURVE_FIGURES))
TABLES = ([f"paper/tables/experiments/{p}_{n}.md" for p, n in experiments()]
          + [f"paper/tables/{p}_{n}.md" for p, n in scripts("tables")])


rule all:
    input:
        "paper/build/paper.html",
        "paper/build/paper.pdf",
        NOTEBOOKS,
        "paper/build/docs/index.html",
        expand("results/scenes/{name}.nc", name=SCENES),


rule codegen:
    """Re-derive every element family; regenerate msslib/generated/, the errata and the derivation results."""
    input:
        list(DERIVATIONS.values()) + ANALYSES + ENGINE,
    output:
        "paper/errata.md",
        "paper/derivations.md",
        "paper/derivations.json",
    log:
        "logs/codegen.log",
    shell:
        "python -m derivations.codegen > {log} 2>&1 && python -m derivations.codegen --check >> {log} 2>&1"


rule scene:
    """Run one example scene (MSS or FEM) into a NetCDF result."""
    input:
        scene="experiments/scenes/{name}.yaml",
        derived="paper/derivations.json",
        code=MSSLIB,
    output:
        "results/scenes/{name}.nc",
    log:
        "logs/scenes/{name}.log",
    shell:
        "python -m msslib run {input.scene} --out {output} --quiet > {log} 2>&1"


# One job per experiment runs all its (case, model) pairs in one process (the imports cost more
# than a small run); each pair is still its own NetCDF file.
def run_spec(path):
    """A digest of an experiment file without its figures block: what its runs depend on. The run rules
    take it as a parameter instead of the file as an input, so that editing a figure reruns no run
    (Snakemake reruns a job whose parameters changed)."""
    raw = yaml.safe_load(Path(path).read_text())
    raw.pop("figures", None)
    return hashlib.sha256(json.dumps(raw, sort_keys=True, default=str).encode()).hexdigest()[:16]


for (_paper, _exp), _path in experiments().items():
    rule:
        name:
            f"experiment_{_paper}_{_exp}"
        input:
            # mesh files the experiments of this paper read (experiments/<paper>/meshes/)
            meshes=sorted(str(p) for p in Path("experiments", _paper, "meshes").glob("*") if p.suffix != ".py"),
            derived="paper/derivations.json",
            code=MSSLIB,
        output:
            [f"results/{_paper}/{_exp}/{r}.nc" for r in runs(_paper, _exp)],
        params:
            exp=str(_path),
            spec=run_spec(_path),
            quick=QFLAG,
            outdir=f"results/{_paper}/{_exp}",
        log:
            f"logs/{_paper}/{_exp}/runs.log",
        shell:
            "python -m msslib experiment run-all {params.exp} --out-dir {params.outdir} {params.quick} --quiet > {log} 2>&1"


rule experiment_compare:
    """Every variant against the reference, beside the published numbers: NetCDF and a table."""
    input:
        exp="experiments/{paper}/{exp}.yaml",
        runs=lambda wc: expand("results/{paper}/{exp}/{run}.nc", paper=wc.paper, exp=wc.exp, run=runs(wc.paper, wc.exp)),
    output:
        nc="results/{paper}/{exp}/comparison.nc",
        table=report("paper/tables/experiments/{paper}_{exp}.md", caption="paper/report/comparison.rst",
                     category="{paper}", subcategory="experiments", labels={"experiment": "{exp}"}),
    log:
        "logs/{paper}/{exp}/compare.log",
    shell:
        "python -m msslib experiment compare {input.exp} --results results/{wildcards.paper}/{wildcards.exp} "
        "--out {output.nc} --table {output.table} > {log} 2>&1"


def shared(wc):
    """Helper modules next to a group's scripts (experiments/<paper>/*.py): edits rebuild."""
    return sorted(str(p) for p in Path("experiments", wc.paper).glob("*.py")) + ["experiments/script.py"]


def study_sources(wc):
    """What a study reads beyond its own script: the other studies of its paper it imports
    (``from experiments.<paper>.studies.<name> import ...``) and the paper's mesh files
    (experiments/<paper>/meshes/), so that editing either reruns it."""
    text = Path("experiments", wc.paper, "studies", f"{wc.name}.py").read_text(encoding="utf-8")
    imported = re.findall(rf"experiments\.{wc.paper}\.studies\.(\w+)", text)
    found = [f"experiments/{wc.paper}/studies/{n}.py" for n in sorted(set(imported)) if n != wc.name]
    meshes = Path("experiments", wc.paper, "meshes")
    return [f for f in found if Path(f).is_file()] + (sorted(str(p) for p in meshes.iterdir() if p.is_file())
                                                       if meshes.is_dir() else [])


rule study:
    """A sweep that does not fit cases x models (e.g. error against strain or nu)."""
    input:
        script="experiments/{paper}/studies/{name}.py",
        shared=shared,
        sources=study_sources,
        # a study may run the paper's experiment files (e.g. over a load range): edits rerun it
        experiments=lambda wc: sorted(str(p) for p in Path("experiments", wc.paper).glob("*.yaml")),
        code=MSSLIB,
        derived="paper/derivations.json",
    output:
        "results/{paper}/studies/{name}.nc",
    params:
        quick=QFLAG,
    log:
        "logs/{paper}/studies/{name}.log",
    shell:
        "python -m experiments.{wildcards.paper}.studies.{wildcards.name} --out {output} {params.quick} > {log} 2>&1"


# What a job needs beyond a default cluster job (profiles/slurm: one core, 2000 MB, 30 minutes) its
# rule declares, so that a scheduler reserves it. Peak memory (resident set) and wall time measured on
# full builds on one busy core; within the defaults: the Baudet cantilever experiment (0.83 GB, 1.5 min),
# the speed-against-error fronts of the cylinder (0.82 GB, 4.8 min) and the membrane (0.49 GB, 3.6 min).
# Quick builds fit the defaults. Local runs (`snakemake -j2`) ignore mem_mb.
if not QUICK:
    # the dense Baudet cantilever: Q2 continuum on 16x4x4 and the Q1 48x12x12 reference, 3.7 GB, 67 s
    use rule study as study_baudet_cantilever_floor with:
        wildcard_constraints:
            paper="baudet",
            name="cantilever_floor",
        resources:
            mem_mb=6000,

    ruleorder: study_baudet_cantilever_floor > study

    # the speed-against-error front of the cantilever down to level 4 (56 k dofs: the Q2 reference, and
    # Baudet's element-reading Newton solve, 48 s per run), every point timed seven times: 2.6 GB (measured
    # when long runs were timed once), 11.3 min on one core
    use rule study as study_performance_front_cantilever with:
        wildcard_constraints:
            paper="performance",
            name="front_cantilever",
        resources:
            mem_mb=4000,

    ruleorder: study_performance_front_cantilever > study

    # the Baudet L-block's Q1 reference at n = 48 (265 k dofs): 3.6 GB, 37 s per solve; the experiment solves
    # it once, study l_block_load twice (line load, face traction), study structural once (beside Q2
    # 12x12x36 for the sheared beam, 2.4 GB)
    use rule study as study_baudet_l_block_reference with:
        wildcard_constraints:
            paper="baudet",
            name="l_block_load|structural",
        resources:
            mem_mb=6000,

    ruleorder: study_baudet_l_block_reference > study

    use rule experiment_baudet_l_block as experiment_baudet_l_block_dense with:
        resources:
            mem_mb=6000,

    ruleorder: experiment_baudet_l_block_dense > experiment_baudet_l_block

    # the sheared beam's Q1 24x24x72 reference: 1.9 GB, 19 s, at the default's edge
    use rule experiment_baudet_shear_beam as experiment_baudet_shear_beam_dense with:
        resources:
            mem_mb=4000,

    ruleorder: experiment_baudet_shear_beam_dense > experiment_baudet_shear_beam


rule figure:
    """A figure script of experiments/<paper>/figures/ (one that computes or draws something of its own)."""
    input:
        script="experiments/{paper}/figures/{name}.py",
        shared=shared,
        plotting="experiments/plotting.py",
        data=lambda wc: declared_inputs(wc.paper, "figures", wc.name),
    output:
        png=report("paper/figures/{paper}_{name}.png", caption="paper/report/figure.rst",
                   category="{paper}", subcategory="figures", labels={"figure": "{name}"}),
        pdf="paper/figures/{paper}_{name}.pdf",
    wildcard_constraints:
        name="|".join(sorted({n for _, n in scripts("figures")})),
    params:
        quick=QFLAG,
    log:
        "logs/{paper}/figures/{name}.log",
    shell:
        "python -m experiments.{wildcards.paper}.figures.{wildcards.name} --out paper/figures/{wildcards.paper}_{wildcards.name} {params.quick} > {log} 2>&1"


rule curve_figure:
    """A figure declared in experiments/<paper>/figures/curves.yaml: a study result as error curves."""
    input:
        spec="experiments/{paper}/figures/curves.yaml",
        result=lambda wc: CURVE_FIGURES[(wc.paper, wc.name)],
        code=["experiments/figures.py", "experiments/plotting.py", "experiments/script.py"],
    output:
        png=report("paper/figures/{paper}_{name}.png", caption="paper/report/figure.rst",
                   category="{paper}", subcategory="figures", labels={"figure": "{name}"}),
        pdf="paper/figures/{paper}_{name}.pdf",
    wildcard_constraints:
        name="|".join(sorted({n for _, n in CURVE_FIGURES})),
    params:
        quick=QFLAG,
    log:
        "logs/{paper}/figures/{name}.log",
    shell:
        "python -m experiments.figures {input.spec} {wildcards.name} --out paper/figures/{wildcards.paper}_{wildcards.name} "
        "{params.quick} > {log} 2>&1"


rule experiment_figure:
    """A figure declared in an experiment file (its figures block), drawn from the experiment's runs."""
    input:
        exp=lambda wc: f"experiments/{wc.paper}/{EXPERIMENT_FIGURES[(wc.paper, wc.name)][0]}.yaml",
        runs=lambda wc: [f"results/{wc.paper}/{EXPERIMENT_FIGURES[(wc.paper, wc.name)][0]}/{c}__{m}.nc"
                         for c, m in figure_runs(EXPERIMENT_FIGURES[(wc.paper, wc.name)][1], wc.name)],
        code=["experiments/figures.py", "experiments/plotting.py", "experiments/script.py"],
    output:
        png=report("paper/figures/{paper}_{name}.png", caption="paper/report/experiment_figure.rst",
                   category="{paper}", subcategory="figures", labels={"figure": "{name}"}),
        pdf="paper/figures/{paper}_{name}.pdf",
    wildcard_constraints:
        name="|".join(sorted({n for _, n in EXPERIMENT_FIGURES})),
    params:
        quick=QFLAG,
    log:
        "logs/{paper}/figures/{name}.log",
    shell:
        "python -m experiments.figures {input.exp} {wildcards.name} --out paper/figures/{wildcards.paper}_{wildcards.name} "
        "{params.quick} > {log} 2>&1"


rule table:
    input:
        script="experiments/{paper}/tables/{name}.py",
        shared=shared,
        data=lambda wc: declared_inputs(wc.paper, "tables", wc.name),
    output:
        report("paper/tables/{paper}_{name}.md", caption="paper/report/table.rst",
               category="{paper}", subcategory="tables", labels={"table": "{name}"}),
    params:
        quick=QFLAG,
    log:
        "logs/{paper}/tables/{name}.log",
    shell:
        "python -m experiments.{wildcards.paper}.tables.{wildcards.name} --out {output} {params.quick} > {log} 2>&1"


rule stability:
    """Hard cases: where each model breaks, and how."""
    input:
        script=sorted(str(p) for p in Path("experiments", "stability").glob("*.py")) + ["experiments/stability/cases.yaml"],
        derived="paper/derivations.json",
        code=MSSLIB,
    output:
        "results/stability.nc",
    params:
        quick=QFLAG,
    log:
        "logs/stability.log",
    shell:
        "python -m experiments.stability --out {output} {params.quick} > {log} 2>&1"


def all_cores():
    """Every core of a local run (--cores); 1 where no total is given (a cluster executor: the
    benchmarks job then reserves its node with --exclusive instead)."""
    try:
        return workflow.cores
    except WorkflowError:
        return 1


rule benchmarks:
    """Speed figures with their baselines: full sizes, with the machine to itself (all cores are
    reserved for it, so that no other job of the workflow runs beside the timings); reduced sizes
    with quick=1 or --config benchmarks=quick."""
    input:
        code=MSSLIB + sorted(str(p) for p in Path("benchmarks").glob("*.py")),
    output:
        "results/benchmarks.json",
    threads: lambda wildcards: all_cores()  # evaluated per job: `snakemake --report` needs no --cores
    resources:
        # on a cluster the job asks for a whole node (one core for itself, none for other jobs)
        slurm_extra="--exclusive",
    params:
        size="--quick" if QUICK or config.get("benchmarks") == "quick" else "",
    log:
        "logs/benchmarks.log",
    shell:
        "python -m benchmarks {params.size} --out {output} > {log} 2>&1"


PAPER_SOURCES = sorted(Path("paper").glob("*.md.in")) + sorted(Path("paper", "sections").glob("*.md"))


rule paper_markdown:
    """The paper's Markdown: the sources with figures, tables and numbers from results filled in."""
    input:
        source=PAPER_SOURCES,
        derived=["paper/errata.md", "paper/derivations.md", "paper/derivations.json"],
        figures=FIGURES,
        tables=TABLES,
        results=COMPARISONS + STUDIES,
        code="experiments/paper.py",
    output:
        "paper/build/paper.md",
    log:
        "logs/paper_markdown.log",
    shell:
        "python -m experiments.paper fill paper/paper.md.in --out {output} > {log} 2>&1"


rule paper_html:
    """The paper as one HTML file: math as MathML and figures embedded, no script, no network."""
    input:
        markdown="paper/build/paper.md",
        figures=FIGURES,
        code="experiments/paper.py",
    output:
        report("paper/build/paper.html", caption="paper/report/paper.rst", category="Paper", labels={"format": "HTML"}),
    log:
        "logs/paper_html.log",
    shell:
        "python -m experiments.paper html {input.markdown} --out {output} > {log} 2>&1"


rule paper_pdf:
    """The paper as PDF: pandoc writes Typst (paper/build/paper.typ), the typst compiler the PDF."""
    input:
        markdown="paper/build/paper.md",
        figures=FIGURES,
        code="experiments/paper.py",
    output:
        pdf=report("paper/build/paper.pdf", caption="paper/report/paper.rst", category="Paper", labels={"format": "PDF"}),
        typst="paper/build/paper.typ",
    log:
        "logs/paper_pdf.log",
    shell:
        "python -m experiments.paper pdf {input.markdown} --out {output.pdf} > {log} 2>&1"


rule derivation_notebook:
    """One derivation module as a notebook page: its cells run in order, prose as text, code with
    what it showed (matrices, equations, solution, checks) as MathML; one self-contained HTML file."""
    input:
        module=lambda wc: DERIVATIONS[wc.module],
        engine=ENGINE,
        code="experiments/paper.py",
    output:
        "paper/build/derivations/{module}.html",
    wildcard_constraints:
        module="|".join(DERIVATIONS),
    log:
        "logs/derivations/{module}.log",
    shell:
        "python -m experiments.paper notebook {wildcards.module} --out {output} > {log} 2>&1"


rule docs:
    """The documentation site (Sphinx, offline): the API from the docstrings, the scene syntax, the
    model and element tables generated from the registries, the worked examples; its element
    table links the derivation pages of rule derivation_notebook beside it. A few seconds."""
    input:
        sources=sorted(str(p) for p in Path("paper", "docs").rglob("*") if p.is_file() and "__pycache__" not in p.parts),
        code=MSSLIB,
        derivations=list(DERIVATIONS.values()),
        examples=sorted(str(p) for p in Path("experiments", "examples").glob("*.py")),
        readme="README.md",
    output:
        "paper/build/docs/index.html",
    log:
        "logs/docs.log",
    shell:
        "python -m sphinx -W -q -b html paper/docs paper/build/docs > {log} 2>&1"
