# msslib workflow: derivations -> generated code and derivation results -> scene runs (NetCDF).
#   snakemake -j2                    everything
#   snakemake -j2 --config quick=1   reduced version of every output (CI)
#   snakemake -n                     show the whole DAG
# Rules are thin: each calls one entry point of derivations/ or msslib.

QUICK = bool(int(config.get("quick", 0)))
DERIVATIONS = ["triangle", "square", "rectangle", "tetrahedron", "cube_baudet", "cube_golec", "kernels"]
ENGINE = ["__init__", "elasticity", "fem", "mss", "match", "lattice", "records", "codegen", "report"]
SCENES = sorted(glob_wildcards("experiments/scenes/{name}.yaml").name)


rule all:
    input:
        "paper/errata.md",
        "paper/derivations.md",
        expand("results/scenes/{name}.nc", name=SCENES),


rule codegen:
    """Re-derive every element family, regenerate msslib/generated/ and the errata."""
    input:
        expand("derivations/{m}.py", m=DERIVATIONS + ENGINE),
    output:
        "paper/errata.md",
        "paper/derivations.md",
        "paper/derivations.json",
    log:
        "logs/codegen.log",
    shell:
        "python -m derivations.codegen > {log} 2>&1 && python -m derivations.codegen --check >> {log} 2>&1"


rule scene:
    """Run one declarative scene (MSS or FEM) into a NetCDF result."""
    input:
        scene="experiments/scenes/{name}.yaml",
        derived="paper/derivations.json",
    output:
        "results/scenes/{name}.nc",
    log:
        "logs/scenes/{name}.log",
    shell:
        "python -m msslib run {input.scene} --out {output} --quiet > {log} 2>&1"
