"""SIGINT and SIGTERM stop a command of the command line within 5 s, also while it is inside a
long C call (here SciPy's SuperLU factorisation, in which Python's own handlers cannot run), exit
non-zero and leave no output file (outputs are written all or nothing)."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

pytestmark = pytest.mark.skipif(not hasattr(signal, "SIGTERM") or os.name != "posix", reason="POSIX signals")

# ``msslib run``, its work replaced by a real factorisation of a 3D Laplacian (natural ordering:
# about 20 s on one core) while an output file is staged
SCRIPT = textwrap.dedent("""
    import sys
    import time

    import scipy.sparse as sp
    import scipy.sparse.linalg as sla

    from msslib import cli
    from msslib.results import StagedOutputs

    def factorise(args):
        n = 30
        one, d = sp.identity(n), sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
        a = (sp.kron(sp.kron(d, one), one) + sp.kron(sp.kron(one, d), one) + sp.kron(sp.kron(one, one), d)).tocsc()
        with StagedOutputs() as out:
            out.write_text(args.out, "a result")
            print("factorising", file=sys.stderr, flush=True)
            t = time.perf_counter()
            sla.splu(a, permc_spec="NATURAL")
            print(f"factorised in {time.perf_counter() - t:.1f} s", file=sys.stderr, flush=True)
        return 0

    cli._cmd_run = factorise
    sys.exit(cli.main(["run", sys.argv[1], "--out", sys.argv[2]]))
""")


def _signals_as_from_a_terminal():
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


@pytest.mark.parametrize("sig, code, said", [(signal.SIGTERM, 143, "msslib: terminated"),
                                             (signal.SIGINT, 130, "msslib: interrupted")])
def test_signal_stops_a_long_factorisation_within_5_s(tmp_path, sig, code, said):
    scene, out = tmp_path / "s.yaml", tmp_path / "out.nc"
    scene.write_text("not read\n")
    # the command as started from a terminal: a test run launched in the background (a shell's
    # "&" without job control) ignores SIGINT, and a child inherits that, as it should
    proc = subprocess.Popen([sys.executable, "-c", SCRIPT, str(scene), str(out)], stderr=subprocess.PIPE, text=True,
                            preexec_fn=_signals_as_from_a_terminal)
    try:
        line = proc.stderr.readline()
        assert line.strip() == "factorising", line
        # the staged temporary file exists: the factorisation runs with an output under way
        assert any(p.name.startswith(".out.nc.msslib-tmp-") for p in tmp_path.iterdir())
        time.sleep(1.0)  # well inside the factorisation
        assert proc.poll() is None
        t0 = time.perf_counter()
        proc.send_signal(sig)
        rc = proc.wait(timeout=30)
        elapsed = time.perf_counter() - t0
        err = proc.stderr.read()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert "factorised" not in err  # it was stopped inside the factorisation, not after it
    assert elapsed < 5.0, elapsed
    assert rc == code, (rc, err)
    assert said in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]  # no output, no temporary file


def test_a_command_that_ends_leaves_no_watching_thread_and_no_error(tmp_path):
    """The watching thread ends with the command (it reads the end of its pipe), without an error."""
    import threading

    from msslib.cli import main

    errors, previous = [], threading.excepthook
    threading.excepthook = lambda args: errors.append(args.exc_value)
    try:
        assert main(["validate", str(tmp_path / "missing.yaml")]) == 1
        for t in threading.enumerate():
            if t.name == "msslib-stop":
                t.join(5)
    finally:
        threading.excepthook = previous
    assert not [t for t in threading.enumerate() if t.name == "msslib-stop"]
    assert errors == []
